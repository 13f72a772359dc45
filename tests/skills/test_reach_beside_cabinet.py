"""A pick beside the tall cabinet follows the arm configurations its plan checked (issue 20).

The 7-joint arm reaches one grasp pose with many elbow and forearm positions. The pick checked one of
them (the base planner's, at the grasp pose) and then descended along straight lines solved from
wherever the arm arrived above the object, with another forearm position: beside the 32 cm cabinet,
with two drawers open, that forearm (link 5) met the carcass on the way down, for every candidate
(``gsrgen_gg_complex_06``, step 5: ``pick yellow_mug1 table`` blocked four times). Now the base planner
checks every configuration of the way down and the pick follows exactly those.

The simulator state is the one saved in that step, with the old pick, the moment the arm had arrived
above the mug's first candidate (``data/``, ``p.saveBullet`` in ``gsrgen_gg_complex_06``, seed 0, after
its steps 1-4: both drawers opened, a cube put in the top one): the pick starts from that arm.
"""

from __future__ import annotations

import pytest
from gsr.skills.library import run_step
from gsr.skills.sim_graph import support_of

from gsr.step_grammar import parse_step_text

pytestmark = pytest.mark.physics


def test_a_mug_beside_the_cabinet_is_picked_along_the_checked_descent(snapshot_world) -> None:
    with snapshot_world("gsrgen_gg_complex_06", "gcg_complex_06_above_mug.bullet") as world:
        cab = world.objects["short_cabinet"]
        mug = world.body_aabb(world.objects["yellow_mug1"].body)
        clo, chi = world.body_aabb(cab.body)
        # the situation: the mug on the table beside the carcass, within its depth, both drawers open
        assert clo[0] < (mug[0][0] + mug[1][0]) / 2 < chi[0] and mug[1][1] < clo[1]
        assert support_of(world, "yellow_mug1") == ("on", "table")
        result = run_step(world, parse_step_text("(pick yellow_mug1 table)"))
        assert result.ok, result.message
        assert support_of(world, "yellow_mug1") == ("held", "")


def test_a_descent_that_would_flip_the_wrist_rebranches_above_the_drawer(snapshot_world) -> None:
    """``gsrgen_ss_complex_16`` step 11, ``place_in yellow_cube5 short_cabinet/drawer_low``: the straight
    move over the drawer arrived with the wrist where the way down needs an IK branch flip (joint 5
    jumps 0.5 rad), ``ik_flip`` four times. The state is saved at that arrival (old motion), the cube
    in the hand; ``move_continuous`` now re-branches in joint space above the spot, and the straight
    way down (the place's descent, ``move_line`` as ``move_until_contact`` makes it) needs no flip."""
    import numpy as np
    from gsr.skills.motion import Motion
    from gsr.skills.robot import GRIPPER

    with snapshot_world("gsrgen_ss_complex_16", "sas_complex_16_above_drawer_low.bullet") as world:
        world.robot.command_gripper(0.0, GRIPPER.grasp_force)
        m = Motion(world)
        m.ignore = {world.objects["yellow_cube5"].body}
        above = m.pose()
        down = [above, (above[0] + np.array([0.0, 0.0, -0.28]), above[1])]
        # the situation: from the arm as it arrived, the way down flips the wrist
        assert m.straight_path(down, world.robot.q()) is None
        m.move_continuous(above, down)
        assert m.straight_path(down, world.robot.q()) is not None
        m.move_line(down[1], check=False)  # raises ik_flip without the re-branch
        assert float(np.linalg.norm(m.pose()[0] - down[1][0])) < 0.01


def test_a_lid_behind_the_cabinet_opens_from_a_base_spot_where_the_arm_is_clear(snapshot_world) -> None:
    """``gsrgen_gg_general_09`` step 5, ``open red_lid_box``: the box stands 17 cm behind the cabinet's
    back face, beside it. The base went to the first spot the stroke's poses reach, where the upper arm
    (link 2) already lay in the carcass: the joint move to the stroke's start was ``blocked`` at its
    first waypoint, four times. ``park_for`` now prefers a spot where the arm at the first pose touches
    nothing. State saved before that step (seed 0, after steps 1-4)."""

    with snapshot_world("gsrgen_gg_general_09", "gcg_general_09_before_lid_open.bullet") as world:
        result = run_step(world, parse_step_text("(open red_lid_box)"))
        assert result.ok, result.message


def test_a_base_slide_past_an_open_drawer_keeps_the_arm_off_it(snapshot_world) -> None:
    """``gsrgen_sod_general_18`` step 4, ``pick blue_mug2 table`` (the mug behind the cabinet, by its
    side), with the top drawer open: the base backed off, slid sideways and came forward beside the
    drawer with the arm held as it was; only the base and the arm's foot were checked, the shoulder
    (link 1) met the open drawer and pushed it shut (``drawer_high: open -> -``, a divergence). The
    route's legs now keep the whole arm clear. State saved before that step (seed 0, steps 1-3)."""

    with snapshot_world("gsrgen_sod_general_18", "sod_general_18_before_mug_pick.bullet") as world:
        cab = world.objects["short_cabinet"]
        assert world.joint_position(cab, "drawer_2") > 0.2  # the top drawer open
        result = run_step(world, parse_step_text("(pick blue_mug2 table)"))
        assert result.ok, result.message
        assert world.joint_position(cab, "drawer_2") > 0.2


def test_a_straight_base_slide_keeps_the_held_arm_off_an_open_drawer(snapshot_world) -> None:
    """``gsrgen_sod_general_09``, ``pick yellow_mug2 table`` with the top drawer open: the pick's checked path
    chose a base spot along the cabinet's front, and the straight slide there was checked for the base only;
    the arm, held as it was, swept into the open drawer and pushed it 0.234 -> 0.153 m shut (still "open" for
    the graph), so later mugs lost their floor spots. The straight slide now keeps the arm clear too
    (``Motion._base_route``). State saved before that step (seed 0, after its earlier steps)."""
    with snapshot_world("gsrgen_sod_general_09", "sod_general_09_before_mug2_pick.bullet") as world:
        cab = world.objects["short_cabinet"]
        assert world.joint_position(cab, "drawer_2") > 0.23  # the top drawer open
        result = run_step(world, parse_step_text("(pick yellow_mug2 table)"))
        assert result.ok, result.message
        assert world.joint_position(cab, "drawer_2") > 0.22
