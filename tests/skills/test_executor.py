"""Closed-loop execution: plans run physically, divergence and invalid steps are diagnosed."""

from __future__ import annotations

import pytest
from gsr.skills.executor import PhysicalExecutor, execute_plan

from gsr.step import Plan, Step


def test_observed_divergence_stops_before_moving(bowl_world) -> None:
    import pybullet as p

    # knock the bowl off the table (test setup): the observed graph no longer has it on the table
    body = bowl_world.objects["akita_black_bowl_1"].body
    p.resetBasePositionAndOrientation(body, (0.0, 2.0, -0.5), (0, 0, 0, 1), physicsClientId=bowl_world.client)
    bowl_world.step(30)
    result = execute_plan(bowl_world, Plan((Step("pick", ("akita_black_bowl_1", "main_table")),)))
    assert not result.ok and result.failed_step == 1
    assert "invalid in the observed state" in result.diagnosis
    assert result.steps[0].skill is None  # nothing moved


def test_executor_runs_a_plan_and_tracks_the_graph(bowl_world) -> None:
    ex = PhysicalExecutor(bowl_world, frame_camera="top")
    result = ex.execute(
        [
            Step("pick", ("akita_black_bowl_1", "main_table")),
            Step("place_on", ("akita_black_bowl_1", "plate_1")),
        ]
    )
    assert result.ok, result.diagnosis
    assert ("akita_black_bowl_1", "on", "plate_1") in {e.key() for e in result.final_graph.edges}
    assert len(result.frames) == 3
    assert all(s.diff is not None and s.diff.is_empty for s in result.steps)


@pytest.mark.physics
def test_libero_goal_plans_execute(libero_dir) -> None:
    from gsr.skills.build import build_world

    from gsr.plan.api import plan_graph
    from tests.skills.conftest import libero_goal_task

    task = libero_goal_task(
        libero_dir,
        "open_the_top_drawer_and_put_the_bowl_inside",
        "(in akita_black_bowl_1 wooden_cabinet_1/top_drawer)",
    )
    found = plan_graph(None, task.initial, task.goal_formula())
    with build_world(task, seed=0) as world:
        result = execute_plan(world, found.plan)
    assert result.ok, result.diagnosis


@pytest.mark.physics
def test_gym_env_episode(bowl_task) -> None:
    from gsr.skills.gym_env import make_env

    env = make_env(bowl_task, width=80, height=60)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and not info["goal_met"]
    _, reward, terminated, _, _ = env.step("(pick akita_black_bowl_1 main_table)")
    assert reward == 0.0 and not terminated
    _, reward, terminated, _, info = env.step("(place_on akita_black_bowl_1 plate_1)")
    assert reward == 1.0 and terminated and info["goal_met"]
    assert env.render().shape == (60, 80, 3)
    env.close()


@pytest.mark.physics
def test_runner_physical_mode(libero_dir) -> None:
    from gsr.benchmarks.runner import RunConfig, episode_job

    from tests.skills.conftest import libero_goal_task

    task = libero_goal_task(libero_dir, "put_the_bowl_on_the_plate", "(on akita_black_bowl_1 plate_1)")
    record = episode_job(task.model_dump(mode="json"), 0, RunConfig(physical=True))
    assert record["success"] and record["steps"] == 2, record["reason"]
