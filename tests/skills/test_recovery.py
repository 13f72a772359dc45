"""Closed-loop recovery for a refused pick (issue 20): neighbours in the hand's way are set aside.

The scene is a generated GSR-Bench Complex cell (shipped code, no third-party data): a 3 cm cube in an
8.5 cm deep box with a mug packed against it on either side along the box, as the plan's order left
it in ``gsrgen_sod_complex_00`` (the blue mugs put in before the yellow cube was taken out).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gsr.benchmarks.suites import get_suite
from gsr.skills.result import Failure

from gsr.facts import state_from_graph
from gsr.resources import load_builtin_domain
from gsr.step_grammar import parse_step_text

pytestmark = pytest.mark.physics


def _task(task_id: str):
    return next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id == task_id)


def _packed(clear_blockers: bool):
    """An executor on sod_complex_00 with both blue mugs packed against the yellow cube in the blue box."""
    import pybullet as p
    from gsr.skills.sim_executor import SimExecutor
    from gsr.skills.sim_graph import scene_graph_from_sim, support_of

    ex = SimExecutor(seed=0, frame_camera=None, clear_blockers=clear_blockers)
    ex.reset(_task("gsrgen_sod_complex_00"), load_builtin_domain("tabletop"))
    w = ex.ex.world
    box, cube = w.objects["blue_box"], w.objects["yellow_cube1"]
    _pos, bq = p.getBasePositionAndOrientation(box.body, physicsClientId=w.client)
    yaw = p.getEulerFromQuaternion(bq)[2]
    sx, sy = box.model.extent[:2]
    along = (
        np.array([math.cos(yaw), math.sin(yaw)]) if sx >= sy else np.array([-math.sin(yaw), math.cos(yaw)])
    )
    cpos, _ = p.getBasePositionAndOrientation(cube.body, physicsClientId=w.client)
    floor = w.body_aabb(cube.body)[0][2]
    for name, side in (("blue_mug1", 1), ("blue_mug2", -1)):
        mug = w.objects[name]
        mpos, mq = p.getBasePositionAndOrientation(mug.body, physicsClientId=w.client)
        xy = np.array(cpos[:2]) + side * along * (0.015 + 0.022 + 0.006)  # 6 mm beside the cube
        z = mpos[2] - w.body_aabb(mug.body)[0][2] + floor + 0.002
        p.resetBasePositionAndOrientation(mug.body, (xy[0], xy[1], z), mq, physicsClientId=w.client)
    for _ in range(240):
        p.stepSimulation(physicsClientId=w.client)
    ex.ex.graph = scene_graph_from_sim(w)
    assert {support_of(w, n) for n in ("blue_mug1", "blue_mug2", "yellow_cube1")} == {("in", "blue_box")}
    return ex


def test_a_pick_blocked_by_packed_neighbours_sets_them_aside_and_succeeds() -> None:
    from gsr.skills.sim_graph import support_of

    step = parse_step_text("(pick yellow_cube1 blue_box)")
    # without the recovery the pick is refused, naming the mugs as in the way
    ex = _packed(clear_blockers=False)
    try:
        refused = ex.execute(step)
        assert not refused.ok and ex.outcomes[-1].skill.failure is Failure.BLOCKED
        assert "(in the way: blue_mug" in refused.message and not ex.recoveries
    finally:
        ex.close()
    ex = _packed(clear_blockers=True)
    try:
        w = ex.ex.world
        cube_xy = (
            w.body_aabb(w.objects["yellow_cube1"].body)[0][:2]
            + w.body_aabb(w.objects["yellow_cube1"].body)[1][:2]
        ) / 2
        d = ex.execute(step)
        # the step is done (its own transition) and reported with what moved; the graph shows the moved
        # neighbours besides, so a closed-loop agent replans from it
        assert d.ok and "executed after a clearance: (pick yellow_cube1 blue_box)" in d.message
        assert "aside on table" in d.message and "then succeeded" in d.message
        assert (
            d.next_state is not None and state_from_graph(ex.graph(), ex.domain).atoms != d.next_state.atoms
        )
        (rec,) = ex.recoveries
        assert rec["picked"] and 1 <= len(rec["moved"]) <= 2
        assert support_of(w, "yellow_cube1") == ("held", "")
        for name in rec["moved"]:
            assert support_of(w, name) == ("on", "table")
            lo, hi = w.body_aabb(w.objects[name].body)
            # set down out of the hand's room round the cube
            assert float(np.max(np.abs((lo[:2] + hi[:2]) / 2 - cube_xy))) > 0.1
        steps = [o.step for o in ex.outcomes]
        assert (
            steps[1] == f"(pick {rec['moved'][0]} blue_box)"
            and steps[2] == f"(place_on {rec['moved'][0]} table)"
        )
        assert ex.outcomes[-1].ok and steps[-1] == str(step)
        # the observed graph the agent replans from shows the cube held and the mugs on the table
        graph = ex.graph()
        assert "held" in next(n for n in graph.nodes if n.id == "yellow_cube1").states
        assert {(e.source, e.target) for e in graph.edges if e.relation == "on"} >= {
            (n, "table") for n in rec["moved"]
        }
    finally:
        ex.close()


def test_a_container_or_a_fixture_in_the_way_is_never_named_for_setting_aside() -> None:
    from gsr.skills.build import build_world
    from gsr.skills.grasping import in_the_way
    from gsr.skills.recovery import blockers

    with build_world(_task("gsrgen_ss_complex_01"), seed=0) as world:
        cube = world.objects["yellow_cube2"]  # in blue_lid_box, which stands on the table by short_cabinet
        msgs = [
            "grasp pose collides with blue_lid_box (base) at the hand",  # its own box
            "from every base position the arm collides: short_cabinet (base) at the link5",  # a fixture
            "grasp pose collides with yellow_cube1 (base) at the left finger",
            "grasp pose collides with blue_mug1 (base) at the hand",
            "path to [0.1, 0.2, 0.3] collides with yellow_cube1 (base) at the right finger",
            "grasp pose collides with yellow_cube2 (base) at the hand",  # itself
            "grasp pose collides with table at the hand",
        ]
        assert in_the_way(world, cube, msgs) == ["yellow_cube1", "blue_mug1"]  # most often named first
        from gsr.skills.sim_graph import scene_graph_from_sim

        graph = scene_graph_from_sim(world)
        said = "cannot reach a grasp on yellow_cube2: ... (in the way: yellow_cube1, blue_mug1)"
        assert blockers(said, world, graph) == ["yellow_cube1", "blue_mug1"]
        assert (
            blockers("cannot reach a grasp on yellow_cube2: grasp pose collides with blue_mug1", world, graph)
            == []
        )


def test_a_neighbour_with_something_on_it_is_taken_apart_from_the_top() -> None:
    from gsr.skills.build import build_world
    from gsr.skills.recovery import blockers
    from gsr.skills.sim_graph import scene_graph_from_sim

    with build_world(_task("gsrgen_sod_complex_00"), seed=0) as world:  # blue_box stands on yellow_box
        graph = scene_graph_from_sim(world)
        said = "cannot reach a grasp on red_cube1: ... (in the way: yellow_box, blue_box)"
        assert blockers(said, world, graph) == ["blue_box"]  # the box on top, once
    # SOD Complex 11: the hand reaching for red_mug1 on the desk meets blue_box, which carries yellow_box
    # (blue_cube1 inside it); the pick of blue_box is invalid, so yellow_box is set aside first
    # (before: nothing was, and the pick stayed refused)
    with build_world(_task("gsrgen_sod_complex_11"), seed=0) as world:
        graph = scene_graph_from_sim(world)
        assert ("yellow_box", "blue_box") in {(e.source, e.target) for e in graph.edges if e.relation == "on"}
        said = "cannot reach a grasp on red_mug1: grasp pose collides with blue_box (base) ... (in the way: blue_box)"
        assert blockers(said, world, graph) == ["yellow_box"]


def _gcg11(clear_blockers: bool):
    from gsr.skills.sim_executor import SimExecutor

    ex = SimExecutor(seed=0, frame_camera=None, clear_blockers=clear_blockers)
    ex.reset(_task("gsrgen_gg_complex_11"), load_builtin_domain("tabletop"))
    return ex


def test_a_mug_packed_by_a_box_end_wall_is_freed_by_setting_aside_what_stands_on_its_way(monkeypatch) -> None:
    from gsr.skills import recovery, sim_executor
    from gsr.skills.sim_graph import support_of

    # GCG Complex 11: three 4.4 cm mugs in one box; yellow_mug1 stands 7 cm from its middle by an end
    # wall, where no grasp's hand clears the walls (a mug is held across its body, never on its
    # handle); the drag towards the middle would run into red_mug1, which the refusal now names
    # (before: it named nothing, the box being the mug's host, and the pick stayed refused)
    step = parse_step_text("(pick yellow_mug1 yellow_box)")
    # since the rim pinch (issue 20, seventh pass) the mug is taken by its rim where it stands
    ex = _gcg11(clear_blockers=False)
    try:
        assert ex.execute(step).ok
        assert support_of(ex.ex.world, "yellow_mug1") == ("held", "")
    finally:
        ex.close()
    # the naming and the drag, for an object no grasp fits: the pinches switched off
    from gsr.skills import grasping

    monkeypatch.setattr(grasping, "rim_pinches", lambda world, obj, limit=6: [])  # grasping's binding
    ex = _gcg11(clear_blockers=False)
    try:
        said = ex.execute(step)
        assert not said.ok
        assert "(in the way: red_mug1)" in said.message
        assert ex.outcomes[-1].skill.failure is Failure.BLOCKED
    finally:
        ex.close()
    # with the recovery: red_mug1 is set aside on the table, then the drag and the pick succeed; a
    # neighbour named first whose own pick is refused (blue_mug1, packed by the same wall) is skipped
    real = recovery.blockers
    monkeypatch.setattr(  # the executor's own binding of recovery.blockers
        sim_executor, "blockers", lambda msg, world, graph: ["blue_mug1", *real(msg, world, graph)]
    )
    ex = _gcg11(clear_blockers=True)
    try:
        ex.execute(step)
        world = ex.ex.world
        assert support_of(world, "yellow_mug1") == ("held", "")
        assert support_of(world, "red_mug1") == ("on", "table")
        assert support_of(world, "blue_mug1") == ("in", "yellow_box")
        assert ex.recoveries[0]["moved"] == ["red_mug1"] and ex.recoveries[0]["picked"]
        assert "blue_mug1 could not be taken" in ex.recoveries[0]["notes"][0]
    finally:
        ex.close()
