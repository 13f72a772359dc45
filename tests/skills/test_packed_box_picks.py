"""Picks out of packed open boxes (issue 20, seventh pass): a small mug by its rim, a cube dragged past a mug.

A small mug packed by a box's end wall is taken by pinching its rim.
``gsrgen_sod_complex_05`` (seed 0), step 5: ``pick blue_mug1 red_box``. The box stands on another box;
``blue_mug1`` stands 8.3 cm from its middle along its long side, by the end wall, with ``yellow_mug1``
beside it. A GSR-Bench 4.4 cm mug held whole closes across its body (never on its handle), which puts a
finger's 3 cm beyond the body on both sides: into the end wall or the neighbour at every yaw, so every
candidate was refused (``grasp pose collides with red_box (base) at the left finger / at the hand``).
A pinch of the rim wall (one finger inside the mug, one outside, closing along a radius) needs that
room on one side only. The simulator state was saved (``p.saveBullet``) at the start of that pick.
"""

from __future__ import annotations

import math

import pytest
from gsr.skills.hand_clearance import PINCH_HANDLE_GAP, rim_pinches, rim_segments
from gsr.skills.library import run_step
from gsr.skills.sim_graph import support_of

from gsr.step_grammar import parse_step_text

pytestmark = pytest.mark.physics


def test_a_mug_by_a_box_end_wall_is_picked_by_its_rim(snapshot_world) -> None:
    with snapshot_world("gsrgen_sod_complex_05", "sod_complex_05_before_mug_pick.bullet") as world:
        assert support_of(world, "blue_mug1") == ("in", "red_box")
        result = run_step(world, parse_step_text("(pick blue_mug1 red_box)"))
        assert result.ok, result.message
        assert support_of(world, "blue_mug1") == ("held", "")
        mug = world.body_aabb(world.objects["blue_mug1"].body)
        assert mug[0][2] > world.body_aabb(world.objects["red_box"].body)[1][2]  # lifted out of the box


def test_rim_pinches_close_along_a_radius_away_from_the_handle(snapshot_world) -> None:
    with snapshot_world("gsrgen_sod_complex_05", "sod_complex_05_before_mug_pick.bullet") as world:
        mug = world.objects["blue_mug1"]
        assert len(rim_segments(mug)) == 14  # the ring's wall segments; the handle is not one
        assert rim_segments(world.objects["red_cube1"]) == []
        pinches = rim_pinches(world, mug)
        assert pinches
        _lo, hi = world.body_aabb(mug.body)
        handle = world.to_world(mug.body, mug.links["base"], mug.model.keypoints["handle"][1])
        import pybullet as p

        axis = p.getBasePositionAndOrientation(mug.body, physicsClientId=world.client)[0]
        for g in pinches:
            radial = math.atan2(g.pos[1] - axis[1], g.pos[0] - axis[0])
            to_handle = math.atan2(handle[1] - axis[1], handle[0] - axis[0])
            assert abs(math.remainder(radial - to_handle, 2 * math.pi)) >= PINCH_HANDLE_GAP - 1e-6
            # on the rim wall (outside the 2.8 cm interior, inside the 4.4 cm body), just below its top
            assert 0.014 < math.hypot(g.pos[0] - axis[0], g.pos[1] - axis[1]) < 0.022
            assert hi[2] - 0.01 < g.pos[2] < hi[2]


def test_a_mug_beside_a_cubes_drag_is_named_for_setting_aside(snapshot_world) -> None:
    """``gsrgen_sod_complex_18``: ``yellow_cube1`` lies 7.4 cm from ``red_box``'s middle along it, by the
    end wall, where no grasp fits; the drag towards the middle is the way out, but the tilted hand
    lying along the box meets ``red_mug1`` (in the box, beside the cube's way) at every tilt. The drag
    names it (before: nothing named, the pick refused with only the box in the way, and the episode
    failed); the executor then sets it aside and the drag and the pick succeed."""
    from gsr.skills.hand_clearance import plan_drag

    with snapshot_world("gsrgen_sod_complex_18", "sod_complex_18_cube_by_end_wall.bullet") as world:
        cube = world.objects["yellow_cube1"]
        assert support_of(world, "yellow_cube1") == ("in", "red_box")
        named: list[str] = []
        assert plan_drag(world, cube, named) == []
        assert named == ["red_mug1"]
        # with the mug away, the drag fits
        import pybullet as p

        mug = world.objects["red_mug1"].body
        p.resetBasePositionAndOrientation(mug, (0.6, 0.6, 0.02), (0, 0, 0, 1), physicsClientId=world.client)
        assert plan_drag(world, cube, [])
