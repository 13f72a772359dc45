"""Where a layout's objects start inside a box (issue 20): where a later pick's hand fits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from gsr.skills.box_slots import GAP_ALONG, box_slots, turned_footprint

from gsr.task_spec import Layout, PlacedObject

CUBE = (0.03, 0.03, 0.03)
#: GSR-Bench's lidded box (17 x 25 x 8.5 cm)
BOX = (0.17, 0.25, 0.085)


def test_two_cubes_go_side_by_side_across_the_middle() -> None:
    room = np.array([0.077, 0.117])  # interior half sizes: y is the long axis
    slots = box_slots([np.array([0.015, 0.015])] * 2, room)
    assert slots is not None and len(slots) == 2
    for uv in slots:
        assert abs(uv[1]) < 1e-9  # on the long axis's middle
    assert slots[0][0] < 0 < slots[1][0] and abs(slots[0][0] + slots[1][0]) < 1e-9


def test_a_full_row_starts_another_along_the_long_side_with_room_for_a_finger() -> None:
    room = np.array([0.117, 0.055])  # x is the long axis here: a row across holds two 4 cm objects
    slots = box_slots([np.array([0.02, 0.02])] * 4, room)
    assert slots is not None
    rows = sorted({round(float(uv[0]), 6) for uv in slots})
    assert len(rows) == 2 and math.isclose(rows[1] - rows[0], 0.04 + GAP_ALONG)
    assert math.isclose(rows[0], -rows[1])


def test_objects_that_do_not_fit_on_the_floor_get_no_slots() -> None:
    assert box_slots([np.array([0.02, 0.02])] * 12, np.array([0.05, 0.08])) is None
    assert box_slots([np.array([0.06, 0.02])], np.array([0.05, 0.08])) is None


def test_a_turned_footprint_is_the_box_round_it() -> None:
    c, h = turned_footprint(np.array([0.0, 0.01]), np.array([0.02, 0.04]), math.pi / 2)
    assert np.allclose(c, [-0.01, 0.0]) and np.allclose(h, [0.04, 0.02])


@pytest.mark.physics
def test_both_cubes_a_layout_puts_in_a_lidded_box_can_be_grasped_with_the_lid_open() -> None:
    pytest.importorskip("pybullet")
    import pybullet as p
    from gsr.skills.build import build_world
    from gsr.skills.hand_clearance import graspable_at

    layout = Layout(
        objects=(
            PlacedObject(id="box", asset="lidded_box", position=(0.05, 0.0, 0.0), size=BOX, yaw=0.3),
            PlacedObject(id="cube1", asset="cube", position=(0.0, 0.0, 0.0), size=CUBE, on="box"),
            PlacedObject(id="cube2", asset="cube", position=(0.0, 0.0, 0.0), size=CUBE, on="box"),
        ),
        table_size=(0.6, 1.2),
    )
    with build_world(layout, seed=0) as w:
        box = w.objects["box"]
        for art in box.model.articulations.values():
            if art.kind == "lid":
                p.resetJointState(box.body, box.links[art.link], art.open, physicsClientId=w.client)
        for oid in ("cube1", "cube2"):
            lo, hi = w.body_aabb(w.objects[oid].body)
            bottom = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
            # the other cube still beside it (the old 3 x 3 grid put the second 7 cm along the box: none)
            assert graspable_at(w, w.objects[oid], bottom), f"no grasp of {oid} fits in the box"
