"""An open sliding lid is a footprint of its own for grasp planning, beside its box."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from gsr.skills.build import build_world
from gsr.skills.grasping import object_footprints, walls_near

from gsr.task_spec import Layout, PlacedObject

BOX = (0.17, 0.25, 0.085)


def _layout(lid: float) -> Layout:
    return Layout(
        objects=(
            PlacedObject(
                id="box", asset="box_with_lid", position=(0.0, 0.0, 0.0), size=BOX, joint_states={"lid": lid}
            ),
            PlacedObject(id="cube", asset="cube", position=(-0.2, 0.3, 0.0), size=(0.03, 0.03, 0.03)),
        ),
        table_size=(0.9, 1.2),
    )


def test_open_lid_is_its_own_footprint_beside_the_box() -> None:
    with build_world(_layout(1.0), seed=0) as w:
        box = w.objects["box"]
        rects = object_footprints(w, box)
        assert len(rects) == 2
        (bc, _, bhalf, btop), (lc, _, lhalf, ltop) = rects
        # the box by its own base (the grip fin moves its centre 2 cm), the lid a full travel away
        assert np.allclose(bc, (0.0, 0.0), atol=0.021)
        assert np.allclose(bhalf, (BOX[0] / 2, BOX[1] / 2 + 0.02), atol=1e-6)
        assert np.allclose(lhalf, (BOX[0] / 2, BOX[1] / 2), atol=1e-6)
        assert float(np.linalg.norm(lc)) == pytest.approx(BOX[1] + 0.005, abs=0.01)
        assert ltop > btop
        # a cube 5 cm past the lid's far end sees it as a wall (15 cm from the whole body's old box)
        beside = lc * (1 + (BOX[1] / 2 + 0.05) / float(np.linalg.norm(lc)))
        cube = w.objects["cube"]
        import pybullet as p

        p.resetBasePositionAndOrientation(cube.body, (*beside, 0.02), (0, 0, 0, 1), physicsClientId=w.client)
        assert walls_near(w, cube, 0.03)


def test_closed_lid_keeps_one_footprint() -> None:
    with build_world(_layout(0.0), seed=0) as w:
        assert len(object_footprints(w, w.objects["box"])) == 1
