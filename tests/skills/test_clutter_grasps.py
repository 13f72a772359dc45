"""Grasping in clutter (issue 20): objects in GSR-Bench's 8.5 cm deep boxes and beside them.

The scenes are the generated GSR-Bench cells (shipped code, no third-party data): a 5 cm mug in a deep
box and a mug on the table against a box wall, where every grasp of the asset model puts the Panda's
hand into a wall.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gsr.benchmarks.suites import get_suite
from gsr.skills import hand_clearance as hc
from gsr.skills.build import build_world
from gsr.skills.grasping import MAX_CLOSES, grasp_candidates, pick, pick_candidates, site_pose
from gsr.skills.motion import Motion
from gsr.skills.result import Failure, SkillError
from gsr.skills.robot import top_down
from gsr.skills.sim_graph import support_of

pytestmark = pytest.mark.physics


def _task(task_id: str):
    return next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id == task_id)


def _proxy_hits(world, obj, pos, quat, opening) -> bool:
    proxy = hc.HandProxy(world)
    try:
        return proxy.hit(np.asarray(pos), quat, opening, hc.near_bodies(world, obj), world.table_body)
    finally:
        proxy.remove()


def test_hand_proxy_sees_a_box_wall_and_not_the_air_above_it() -> None:
    with build_world(_task("gsrgen_gg_complex_01"), seed=0) as world:
        mug = world.objects["yellow_mug1"]
        assert support_of(world, mug.id) == ("in", "yellow_box")
        box = world.objects["yellow_box"]
        lo, hi = world.body_aabb(box.body)
        wall = np.array([lo[0], (lo[1] + hi[1]) / 2, hi[2] - 0.02])  # a point on the near wall's top
        assert _proxy_hits(world, mug, wall, top_down(0.0), 0.05)
        assert not _proxy_hits(world, mug, wall + np.array([0, 0, 0.2]), top_down(0.0), 0.05)
        n_bodies = len({world.objects[k].body for k in world.objects})
        import pybullet as p

        # the proxies are gone afterwards: the world holds the robot, the table and its objects only
        assert p.getNumBodies(physicsClientId=world.client) == n_bodies + 2


def test_a_mug_in_a_deep_box_is_gripped_high_enough_for_the_hand_to_clear_the_walls() -> None:
    with build_world(_task("gsrgen_gg_complex_01"), seed=0) as world:
        mug = world.objects["yellow_mug1"]
        model = grasp_candidates(world, mug)
        # the asset's own grasps (the body's middle) put the hand into the box: the reported baseline
        assert all(_proxy_hits(world, mug, pos, quat, min(0.08, w + 0.035)) for pos, quat, w in model)
        cands = pick_candidates(world, mug)
        site, _ = site_pose(world, mug, mug.model.grasps[0])
        first = cands[0]
        assert first[0][2] > site[2] + 0.01  # gripped near its top
        assert not _proxy_hits(world, mug, *first)
        m = Motion(world, 15000)
        pick(world, m, mug)
        assert support_of(world, mug.id) == ("held", "")


def test_a_mug_against_a_box_wall_is_taken_with_a_tilted_hand() -> None:
    with build_world(_task("gsrgen_sod_complex_01"), seed=0) as world:
        mug = world.objects["red_mug1"]
        assert support_of(world, mug.id) == ("on", "table")
        cands = pick_candidates(world, mug)
        tilted = [c for c in cands if abs(_tilt(c[1])) > 0.1]
        assert tilted, "no tilted candidate"
        pick(world, Motion(world, 15000), mug)
        assert support_of(world, mug.id) == ("held", "")


def _tilt(quat) -> float:
    """Angle (rad) of the hand's closing axis out of the horizontal."""
    import pybullet as p

    y = np.array(p.getMatrixFromQuaternion(list(quat))).reshape(3, 3)[:, 1]
    return math.asin(float(np.clip(y[2], -1, 1)))


def test_a_missed_grasp_is_retried_and_bounded(monkeypatch) -> None:
    with build_world(_task("gsrgen_gg_complex_01"), seed=0) as world:
        mug = world.objects["yellow_mug1"]
        m = Motion(world, 30000)
        closes = {"n": 0}
        real = m.grasp_close

        def miss_once() -> bool:
            closes["n"] += 1
            if closes["n"] == 1:
                m.gripper(0.0, steps=12)
                return False
            return real()

        monkeypatch.setattr(m, "grasp_close", miss_once)
        pick(world, m, mug)
        assert closes["n"] == 2 and support_of(world, mug.id) == ("held", "")

    # never more than MAX_CLOSES closes: a hand that always misses ends with a typed failure
    with build_world(_task("gsrgen_gg_complex_01"), seed=0) as world:
        m = Motion(world, 40000)
        calls = {"n": 0}

        def always_miss() -> bool:
            calls["n"] += 1
            m.gripper(0.0, steps=12)
            return False

        monkeypatch.setattr(m, "grasp_close", always_miss)
        with pytest.raises(SkillError) as err:
            pick(world, m, world.objects["yellow_mug1"])
        assert err.value.failure in (Failure.GRASP_MISSED, Failure.BLOCKED)
        assert 1 <= calls["n"] <= MAX_CLOSES


def test_a_blocked_pick_names_the_obstacle_and_the_hand_part() -> None:
    with build_world(_task("gsrgen_ss_complex_01"), seed=0) as world:
        cube = world.objects["yellow_cube1"]  # in a lidded box whose lid is closed
        with pytest.raises(SkillError) as err:
            pick(world, Motion(world, 15000), cube)
        assert err.value.failure is Failure.BLOCKED
        assert "blue_lid_box" in err.value.message and "at the hand" in err.value.message


def test_a_refused_step_is_not_planned_again_in_the_same_scene(monkeypatch) -> None:
    from gsr.skills import library
    from gsr.skills.sim_executor import SimExecutor

    from gsr.resources import load_builtin_domain
    from gsr.step_grammar import parse_step_text

    calls = {"n": 0}

    def refused(world, m, args):
        calls["n"] += 1
        raise SkillError(Failure.BLOCKED, f"cannot reach a grasp on {args[0]}: grasp pose collides with x")

    monkeypatch.setitem(library.SKILLS, "pick", refused)
    ex = SimExecutor(seed=0, frame_camera=None)
    try:
        ex.reset(_task("gsrgen_sod_complex_01"), load_builtin_domain("tabletop"))
        step = parse_step_text("(pick red_mug1 table)")
        first, again = ex.execute(step), ex.execute(step)
        assert not first.ok and not again.ok and calls["n"] == 1
        assert "not planned again" in again.message and "blocked" in again.message
        assert len(ex.outcomes) == 2 and ex.outcomes[1].skill.failure is Failure.BLOCKED
        # once the scene changes (here: a mug moved by hand), the step is planned again
        import pybullet as p

        mug = ex.ex.world.objects["blue_mug1"]
        pos, quat = p.getBasePositionAndOrientation(mug.body, physicsClientId=ex.ex.world.client)
        p.resetBasePositionAndOrientation(
            mug.body, (pos[0], pos[1] + 0.02, pos[2]), quat, physicsClientId=ex.ex.world.client
        )
        ex.execute(step)
        assert calls["n"] == 2
    finally:
        ex.close()


def test_a_cube_by_a_deep_boxs_end_wall_is_dragged_inwards_then_picked() -> None:
    import pybullet as p

    with build_world(_task("gsrgen_ss_complex_00"), seed=0) as world:
        c = world.client
        box = world.objects["yellow_lid_box"]
        # the scene after the lid was opened and the mug on it and the cube in the middle were taken
        # away (set aside directly: this test is about the cube left by the end wall)
        for oid, xy in (("yellow_mug1", (-0.2, -0.5)), ("blue_cube1", (-0.2, 0.5))):
            body = world.objects[oid].body
            _, quat = p.getBasePositionAndOrientation(body, physicsClientId=c)
            p.resetBasePositionAndOrientation(body, (xy[0], xy[1], 0.03), quat, physicsClientId=c)
        p.resetJointState(box.body, box.links["lid"], 0.255, physicsClientId=c)
        world.step(120)
        cube = world.objects["blue_cube2"]
        assert support_of(world, cube.id) == ("in", "yellow_lid_box")
        # the build starts the cube in the box's middle (skills/box_slots.py): put it 6.5 cm along the box
        # from there towards the end away from the open lid (beyond the ~3 cm band where a grasp fits),
        # where a cube let go into the box can come to rest. (One touching the end wall, 9 cm out, is not
        # dragged: no tilt of the hand lying along the box clears that wall.)
        centre, yaw, half = hc.container_frame(world, cube)
        long_yaw = yaw + (math.pi / 2 if half[1] > half[0] else 0.0)
        along = np.array([math.cos(long_yaw), math.sin(long_yaw)])
        lid = np.array(p.getLinkState(box.body, box.links["lid"], physicsClientId=c)[0][:2])
        away = -1.0 if float((lid - np.asarray(centre[:2])) @ along) > 0 else 1.0
        pos, quat = p.getBasePositionAndOrientation(cube.body, physicsClientId=c)
        xy = np.asarray(centre[:2]) + away * 0.065 * along
        p.resetBasePositionAndOrientation(cube.body, (xy[0], xy[1], pos[2] + 0.002), quat, physicsClientId=c)
        world.step(120)
        assert support_of(world, cube.id) == ("in", "yellow_lid_box")
        drags = hc.plan_drag(world, cube)
        # first towards the middle (a hand along the box fits there)
        assert drags and 0.03 < float(np.linalg.norm(drags[0].shift)) < 0.1
        # no grasp fits where it lies: every candidate's hand or fingers meet the box
        assert all(_proxy_hits(world, cube, *cand) for cand in pick_candidates(world, cube))
        pick(world, Motion(world, 30000), cube)
        assert support_of(world, cube.id) == ("held", "")


def test_a_drawer_close_that_ends_short_is_pushed_home_so_the_drawer_below_opens() -> None:
    from gsr.skills.library import run_step

    from gsr.step_grammar import parse_step_text

    with build_world(_task("gsrgen_gg_complex_02"), seed=0) as world:
        cab = world.objects["short_cabinet"]
        for text in (  # the planner's first five steps
            "(pick yellow_cube1 table)",
            "(place_in yellow_cube1 short_cabinet/drawer_high)",
            "(pick yellow_mug1 yellow_box)",
            "(place_in yellow_mug1 short_cabinet/drawer_high)",
            "(close short_cabinet/drawer_high)",
        ):
            result = run_step(world, parse_step_text(text))
            assert result.ok, (text, result.message)
        # one push left it 9 cm out ("closed": under half its travel), in the way of the hand below
        assert world.joint_position(cab, "drawer_2") < 0.02
        result = run_step(world, parse_step_text("(open short_cabinet/drawer_low)"))
        assert result.ok, result.message


def test_a_box_taken_off_a_box_is_set_down_on_a_crowded_desk() -> None:
    from gsr.skills.library import run_step

    from gsr.step_grammar import parse_step_text

    # GSR-Bench Complex stacks its 25 x 17 cm boxes on a full desk; before, the hand going down with the
    # box stopped at the cube riding in it ("the hand stops 0.09 m above the release point")
    with build_world(_task("gsrgen_sod_complex_00"), seed=0) as world:
        assert support_of(world, "blue_box") == ("on", "yellow_box")
        rider = support_of(world, "yellow_cube1")
        assert rider == ("in", "blue_box")
        for text in ("(pick blue_box yellow_box)", "(place_on blue_box table)"):
            result = run_step(world, parse_step_text(text))
            assert result.ok, (text, result.message)
        assert support_of(world, "blue_box") == ("on", "table")
        assert support_of(world, "yellow_cube1") == ("in", "blue_box")
        # nothing else ended in or on the box it was set down on
        others = [o for o in world.objects if o not in ("blue_box", "yellow_cube1")]
        assert not [o for o in others if (support_of(world, o) or ("", ""))[1] == "blue_box"]


def _box_axes(world, box) -> tuple:
    """A box's base position, unit vectors along its long side and across it, and its two extents."""
    import pybullet as p

    bpos, bq = p.getBasePositionAndOrientation(box.body, physicsClientId=world.client)
    yaw = p.getEulerFromQuaternion(bq)[2]
    sx, sy = box.model.extent[:2]
    along = (
        np.array([math.cos(yaw), math.sin(yaw)]) if sx >= sy else np.array([-math.sin(yaw), math.cos(yaw)])
    )
    return bpos, along, np.array([-along[1], along[0]]), sx, sy


def test_graspable_at_tells_a_deep_box_spot_a_later_pick_can_reach_from_one_it_cannot() -> None:
    import pybullet as p
    from gsr.skills.hand_clearance import graspable_at

    with build_world(_task("gsrgen_sod_complex_00"), seed=0) as world:
        box, cube = world.objects["blue_box"], world.objects["yellow_cube1"]
        assert support_of(world, cube.id) == ("in", "blue_box")
        bpos, along, across, sx, sy = _box_axes(world, box)
        half_len, half_w = max(sx, sy) / 2 - 0.01 - 0.017, min(sx, sy) / 2 - 0.01 - 0.017  # inside the walls
        floor = world.body_aabb(cube.body)[0][2]
        before = p.getBasePositionAndOrientation(cube.body, physicsClientId=world.client)

        def at(a: float, b: float) -> bool:
            xy = np.asarray(bpos[:2]) + along * a * half_len + across * b * half_w
            return graspable_at(world, cube, np.array([xy[0], xy[1], floor]))

        assert at(0.0, 0.0)  # the box's middle: the hand fits in along the box
        assert (
            not at(1.0, 0.0) and not at(1.0, 1.0) and not at(0.0, 1.0)
        )  # against an end wall, a corner, a side
        after = p.getBasePositionAndOrientation(cube.body, physicsClientId=world.client)
        assert np.allclose(before[0], after[0]) and np.allclose(before[1], after[1])  # put back exactly


def test_a_cube_bound_for_a_deep_boxs_corner_is_let_go_where_a_later_pick_reaches_it() -> None:
    from gsr.skills.grasping import graspable_later
    from gsr.skills.hand_clearance import graspable_at

    with build_world(_task("gsrgen_sod_complex_00"), seed=0) as world:
        box, cube = world.objects["blue_box"], world.objects["yellow_cube1"]
        bpos, along, across, sx, sy = _box_axes(world, box)
        floor = world.body_aabb(cube.body)[0][2]
        corner = np.asarray(bpos[:2]) + along * (max(sx, sy) / 2 - 0.027) + across * (min(sx, sy) / 2 - 0.027)
        spot, turn = graspable_later(world, cube, "blue_box", (np.array([corner[0], corner[1], floor]), 0.0))
        assert turn == 0.0 and float(np.linalg.norm(spot[:2] - corner)) > 0.05  # moved off the corner
        assert graspable_at(world, cube, spot)
        # a spot a later pick reaches is kept as the packing chose it
        again, _ = graspable_later(world, cube, "blue_box", (spot, 0.0))
        assert np.allclose(again, spot)
        # not for the table or a drawer: only a box's own interior
        table = np.array([0.0, 0.0, world.body_aabb(world.table_body)[1][2]])
        assert np.allclose(graspable_later(world, cube, "table", (table, 0.0))[0], table)


def test_every_wall_grasp_of_a_rectangular_box_is_on_a_wall_and_the_box_comes_up() -> None:
    import pybullet as p
    from gsr.skills.library import run_step

    from gsr.step_grammar import parse_step_text

    # GSR-Bench's 17 x 25 cm box, a mug in it, standing on another box. The copies of the wall grasp
    # round the box used the first wall's radius: on the short walls they stood 4.5 cm inside the box
    # and closed on nothing or on the mug (grasp_missed / grasp_slipped, every retry)
    with build_world(_task("gsrgen_sod_complex_02"), seed=0) as world:
        box = world.objects["yellow_box"]
        assert support_of(world, box.id) == ("on", "red_box")
        assert support_of(world, "red_mug1") == ("in", box.id)
        sx, sy = box.model.extent[:2]
        bpos, bq = p.getBasePositionAndOrientation(box.body, physicsClientId=world.client)
        inv = p.invertTransform(bpos, bq)
        cands = grasp_candidates(world, box)
        assert len(cands) == 4
        walls = set()
        for pos, _quat, width in cands:
            local = np.array(p.multiplyTransforms(inv[0], inv[1], list(pos), (0, 0, 0, 1))[0])
            on_x = abs(abs(local[0]) - (sx / 2 - width / 2)) < 1e-3 and abs(local[1]) < 1e-3
            on_y = abs(abs(local[1]) - (sy / 2 - width / 2)) < 1e-3 and abs(local[0]) < 1e-3
            assert on_x or on_y, local
            walls.add(("x", local[0] > 0) if on_x else ("y", local[1] > 0))
        assert len(walls) == 4  # one grasp on each wall
        result = run_step(world, parse_step_text("(pick yellow_box red_box)"))
        assert result.ok, result.message
        assert support_of(world, box.id) == ("held", "")
        assert support_of(world, "red_mug1") == ("in", box.id)


def test_a_release_that_stops_high_finds_a_spot_in_the_box_where_the_hand_clears() -> None:
    from gsr.skills.grasping import hand_clear_spot
    from gsr.skills.library import run_step

    from gsr.step_grammar import parse_step_text

    # a cube in the hand over a deep box: in the box's corner the 20 cm hand meets a wall (a release
    # there stops high); hand_clear_spot gives the nearest spot inside the box, off what it already
    # holds, where the hand at the release point and above it touches nothing
    with build_world(_task("gsrgen_sod_complex_02"), seed=0) as world:
        result = run_step(world, parse_step_text("(pick red_cube2 table)"))
        assert result.ok, result.message
        cube, box = world.objects["red_cube2"], world.objects["blue_box"]
        bpos, along, across, sx, sy = _box_axes(world, box)
        floor = float(world.body_aabb(box.body)[0][2]) + 0.01
        corner = np.asarray(bpos[:2]) + along * (max(sx, sy) / 2 - 0.03) + across * (min(sx, sy) / 2 - 0.03)
        spot = np.array([corner[0], corner[1], floor])
        # the wrist turned so the fingers close along the box (as the packing turns it going in)
        import pybullet as p

        rot = np.array(p.getMatrixFromQuaternion(world.robot.ee_pose()[1])).reshape(3, 3)
        turn = math.atan2(along[1], along[0]) - math.atan2(rot[1, 1], rot[0, 1])
        assert not hc.hand_clear_at(world, cube, spot, turn)
        other = hand_clear_spot(world, cube, "blue_box", spot, turn)
        assert other is not None
        assert hc.hand_clear_at(world, cube, other, turn)
        rel = other[:2] - np.asarray(bpos[:2])
        assert abs(float(rel @ along)) < max(sx, sy) / 2 - 0.015
        assert abs(float(rel @ across)) < min(sx, sy) / 2 - 0.015
        # off the cube already in the box
        rlo, rhi = world.body_aabb(world.objects["red_cube1"].body)
        assert support_of(world, "red_cube1") == ("in", "blue_box")
        gap = np.abs(other[:2] - (rlo[:2] + rhi[:2]) / 2) - (rhi[:2] - rlo[:2]) / 2
        assert float(gap.max()) > 0.015
        assert float(np.linalg.norm(other[:2] - spot[:2])) > 0.01
