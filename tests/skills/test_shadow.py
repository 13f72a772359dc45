"""Objects behind a tall fixture (issue 20): the world build moves one no pick reaches, and only such."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from gsr.skills.build import build_world
from gsr.skills.shadow import pickable

from gsr.task_spec import Layout, PlacedObject

pytestmark = pytest.mark.physics

CUBE = (0.03, 0.03, 0.03)


def _layout(cube_xy: tuple[float, float]) -> Layout:
    # GSR-Bench's desk (60 cm deep); the robot's rail runs along its near edge (-x)
    return Layout(
        objects=(
            PlacedObject(id="cabinet", asset="short_cabinet", position=(-0.08, 0.0, 0.0), fixed=True),
            PlacedObject(id="cube", asset="cube", position=(*cube_xy, 0.0), size=CUBE),
        ),
        table_size=(0.6, 1.2),
    )


def test_a_cube_no_pick_reaches_behind_the_cabinet_is_moved_where_one_does() -> None:
    import pybullet as p

    layout = _layout((0.2, 0.0))
    with build_world(layout, seed=0) as w:
        cube = w.objects["cube"]
        assert "cube" in w.adjusted, "the cube stayed behind the cabinet"
        assert pickable(w, cube)
        # where the layout put it, the wrist meets the carcass from every base spot
        _, orn = p.getBasePositionAndOrientation(cube.body, physicsClientId=w.client)
        z = p.getBasePositionAndOrientation(cube.body, physicsClientId=w.client)[0][2]
        p.resetBasePositionAndOrientation(cube.body, (0.2, 0.0, z), orn, physicsClientId=w.client)
        assert not pickable(w, cube)


def test_a_reachable_cube_behind_the_cabinet_stays() -> None:
    # beside the carcass's back corner: the arm reaches past its side
    with build_world(_layout((0.12, 0.26)), seed=0) as w:
        assert "cube" not in w.adjusted
        assert pickable(w, w.objects["cube"])
