"""Motion continuity (IK branch flips), coupled fingers, fixture layout, GSR-Bench sizes, the microwave door."""

from __future__ import annotations

import re

import numpy as np
import pytest
from gsr.skills.motion import MAX_JOINT_JUMP, Motion
from gsr.skills.result import Failure, SkillError

from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.step import Step
from gsr.task_spec import TaskSpec


def _segment(world) -> tuple:
    """A short straight segment below the hand's current pose (10 waypoints)."""
    m = Motion(world)
    pos, quat = m.pose()
    return m, (pos, quat), (pos + np.array([0.0, 0.0, -0.1]), quat)


def test_ik_branch_flip_is_a_typed_failure_before_anything_moves(bowl_world, monkeypatch) -> None:
    m, start, goal = _segment(bowl_world)
    real = m.solve
    calls = {"n": 0}

    def flipping(pos, quat, seed=None):
        calls["n"] += 1
        q = real(pos, quat, seed=seed)
        if calls["n"] == 4:  # the elbow swings to the other branch half way down
            q = q.copy()
            q[5] += 1.5
        return q

    monkeypatch.setattr(m, "solve", flipping)
    monkeypatch.setattr(m.robot, "refine", lambda q0, pos, quat, iters=150: q0 + 1.0)  # no local fix
    before = m.robot.q()
    with pytest.raises(SkillError) as err:
        m.line(start, goal, before)
    assert err.value.failure is Failure.IK_FLIP
    assert re.search(r"branch flip \(arm joint 4 jumps 1\.[45]\d rad", err.value.message), err.value.message
    assert np.allclose(m.robot.q(), before)  # planning only: the arm did not move
    assert m.used == 0


def test_ik_branch_flip_is_repaired_by_a_local_solution(bowl_world, monkeypatch) -> None:
    m, start, goal = _segment(bowl_world)
    real = m.solve
    calls = {"n": 0}

    def flipping(pos, quat, seed=None):
        calls["n"] += 1
        q = real(pos, quat, seed=seed)
        if calls["n"] == 4:
            q = q.copy()
            q[5] += 1.5
        return q

    monkeypatch.setattr(m, "solve", flipping)
    qs = m.line(start, goal, m.robot.q())
    assert len(qs) == 10
    prev = m.robot.q()
    for q in qs:  # continuous: the refined waypoint stays on the arm's branch
        assert float(np.max(np.abs(q[2:] - prev[2:]))) <= MAX_JOINT_JUMP
        prev = q
    dp, _ = m.robot.fk_error(qs[3], start[0] + (goal[0] - start[0]) * 0.4, start[1])
    assert dp < 0.008


def test_a_lift_from_a_wrist_at_its_stop_re_branches_instead_of_failing(bowl_world) -> None:
    """A tilted hand left with joint 6 at its upper stop (as a drawer pull leaves it at the desk's side):
    lifting straight up would cross the stop, so the straight path needs a branch flip; the lift moves
    in joint space to a solution away from the limit instead (issue 20: four GSR-Bench tasks)."""
    from gsr.skills.arm_moves import lift

    m, r = Motion(bowl_world), bowl_world.robot
    q = r.q().copy()
    q[2:9] = (-1.016, -0.207, 0.339, -2.214, -2.344, 3.821, 2.745)
    assert q[7] > r.upper[7] - 0.01  # the premise: joint 6 at its stop
    r.reset(q)
    r.hold(q)
    pos, quat = m.pose()
    top = pos + np.array([0.0, 0.0, 0.05])
    with pytest.raises(SkillError) as err:  # the premise: the straight lift flips
        m.line((pos, quat), (top, quat), r.q(), check=False)
    assert err.value.failure is Failure.IK_FLIP
    lift(m, float(top[2]))
    dp, da = r.fk_error(r.q(), top, quat)
    assert dp < 0.01 and da < 0.1, (dp, da)  # up, orientation kept
    assert r.q()[7] < r.upper[7] - 0.1  # off the stop
    assert m.used > 0


def test_fingers_are_coupled(bowl_world) -> None:
    import pybullet as p

    m = Motion(bowl_world)
    m.gripper(0.03, steps=120)
    a, b = (s[0] for s in p.getJointStates(m.robot.body, m.robot.fingers, physicsClientId=bowl_world.client))
    assert a + b == pytest.approx(0.03, abs=0.004)
    assert abs(a - b) < 0.002


def _fixtures_graph() -> SceneGraph:
    nodes = [Node(id="table", category="table")]
    edges = []
    for name in ("cabinet", "stove", "microwave"):
        nodes.append(Node(id=f"{name}_1", category=name, attributes={"fixture": True}))
        edges.append(Edge(source=f"{name}_1", relation="on", target="table"))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges))


def test_generated_fixtures_do_not_overlap() -> None:
    from gsr.skills.assets import make_asset
    from gsr.skills.layout import TABLE, layout_from_graph

    placed = layout_from_graph(_fixtures_graph(), seed=0).objects
    rects = []
    for o in placed:
        ext = make_asset(o.asset).extent
        x, y = o.position[:2]
        assert abs(x) + ext[0] / 2 <= TABLE[0] / 2 and abs(y) + ext[1] / 2 <= TABLE[1] / 2
        rects.append((x, y, ext[0] / 2, ext[1] / 2))
    for i, (x, y, hx, hy) in enumerate(rects):
        for x2, y2, hx2, hy2 in rects[i + 1 :]:
            assert abs(x - x2) >= hx + hx2 or abs(y - y2) >= hy + hy2


def test_microwave_door_swings_out_towards_the_front() -> None:
    import pybullet as p
    from gsr.skills.build import build_world

    task = TaskSpec(id="mw", suite="t", instructions=("mw",), initial=_fixtures_graph(), goal="(and)")
    with build_world(task, seed=0) as world:
        o = world.objects["microwave_1"]
        art = o.model.articulations["door"]
        link = o.links["door"]
        assert world.joint_position(o, "door") == pytest.approx(0.0, abs=0.01)
        front = world.body_aabb(o.body)[0][0]
        closed = world.to_world(o.body, link, art.handle.xyz)
        p.resetJointState(o.body, link, 1.2, physicsClientId=world.client)
        opened = world.to_world(o.body, link, art.handle.xyz)
        assert opened[0] < front - 0.1 < closed[0]  # out in front of the cavity, not into it


def test_gsr_bench_world_uses_the_benchmarks_own_sizes(shared_data) -> None:
    from gsr.benchmarks.suites.gsr_bench import load_gsr_bench
    from gsr.skills.build import build_world

    task = load_gsr_bench(shared_data / "gsr_bench" / "saved_configs_dev.yaml", numbers=[1])[0]
    with build_world(task, seed=0) as world:
        cube = next(o for o in world.objects.values() if o.model.name == "cube")
        assert cube.model.extent == pytest.approx((0.03, 0.03, 0.03))
        box = next(o for o in world.objects.values() if o.model.name == "box")
        inner = box.model.interiors[""].size
        assert inner[0] == pytest.approx(0.154, abs=0.005) and inner[1] == pytest.approx(0.234, abs=0.005)
        lo, _hi = world.body_aabb(cube.body)
        assert lo[2] == pytest.approx(world.layout.table_height, abs=0.01)  # resting on the desk


@pytest.mark.physics
@pytest.mark.parametrize("seed", [0, 1])
def test_microwave_door_open_and_close(seed: int) -> None:
    from gsr.skills.build import build_world
    from gsr.skills.library import run_step

    task = TaskSpec(id="mw", suite="t", instructions=("mw",), initial=_fixtures_graph(), goal="(and)")
    with build_world(task, seed=seed) as world:
        o = world.objects["microwave_1"]
        opened = run_step(world, Step("open", ("microwave_1",)))
        assert opened.ok, opened.message
        assert world.joint_position(o, "door") > 0.8
        closed = run_step(world, Step("close", ("microwave_1",)))
        assert closed.ok, closed.message
        assert world.joint_position(o, "door") < 0.8


@pytest.mark.physics
def test_a_gsr_bench_simple_task_packs_all_cubes(shared_data) -> None:
    from gsr.benchmarks.agents import make_agent
    from gsr.benchmarks.runner import run_episode
    from gsr.benchmarks.suites.gsr_bench_gen import generate_cell
    from gsr.skills.sim_executor import SimExecutor

    from gsr.resources import load_builtin_domain

    task = generate_cell("Semantic Object Disambiguation", "Simple", n=1, seed=0)[0]
    ex = SimExecutor(seed=0, frame_camera=None)
    try:
        r = run_episode(task, make_agent("planner", {}), load_builtin_domain("tabletop"), executor=ex)
    finally:
        ex.close()
    assert r.success, r.reason
