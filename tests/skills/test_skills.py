"""Meta-skills: a physical pick-and-place (default run), typed failures, budgets."""

from __future__ import annotations

import pytest
from gsr.skills.library import run_step
from gsr.skills.result import Failure
from gsr.skills.sim_graph import support_of

from gsr.step import Step


def test_pick_and_place_by_friction(bowl_world) -> None:
    picked = run_step(bowl_world, Step("pick", ("akita_black_bowl_1", "main_table")))
    assert picked.ok, picked.message
    assert support_of(bowl_world, "akita_black_bowl_1") == ("held", "")
    placed = run_step(bowl_world, Step("place_on", ("akita_black_bowl_1", "plate_1")))
    assert placed.ok, placed.message
    assert support_of(bowl_world, "akita_black_bowl_1") == ("on", "plate_1")
    assert placed.sim_steps > 100


def test_budget_stops_a_skill_with_timeout(bowl_world) -> None:
    result = run_step(bowl_world, Step("pick", ("akita_black_bowl_1", "main_table")), budget=50)
    assert not result.ok and result.failure is Failure.TIMEOUT
    assert result.sim_steps <= 50


def test_unsupported_steps_are_typed(bowl_world) -> None:
    assert run_step(bowl_world, Step("open", ("plate_1",))).failure is Failure.UNSUPPORTED
    assert run_step(bowl_world, Step("fly", ("plate_1",))).failure is Failure.UNSUPPORTED
    assert (
        run_step(bowl_world, Step("pick", ("wooden_cabinet_1", "main_table"))).failure is Failure.UNSUPPORTED
    )


def test_place_without_holding_reports_it(bowl_world) -> None:
    result = run_step(bowl_world, Step("place_on", ("akita_black_bowl_1", "plate_1")))
    assert result.failure is Failure.GRASP_SLIPPED


@pytest.mark.physics
@pytest.mark.parametrize(
    "steps",
    [
        [Step("open", ("wooden_cabinet_1/top_drawer",)), Step("close", ("wooden_cabinet_1/top_drawer",))],
        [Step("turn_on", ("flat_stove_1",))],
        [Step("push", ("plate_1", "main_table", "main_table/stove_front_region"))],
    ],
)
def test_articulated_and_push_skills(libero_dir, steps) -> None:
    from gsr.skills.build import build_world

    from tests.skills.conftest import libero_goal_task

    name = "push_the_plate_to_the_front_of_the_stove"
    with build_world(libero_goal_task(libero_dir, name), seed=0) as world:
        for step in steps:
            result = run_step(world, step)
            assert result.ok, f"{step}: {result.message}"


def test_debug_weld_is_off_by_default_and_explicit(bowl_task) -> None:
    from gsr.skills.build import build_world

    with build_world(bowl_task, seed=0) as world:
        assert world.debug_weld is False
        assert run_step(world, Step("pick", ("akita_black_bowl_1", "main_table"))).ok
        assert world.welds == {}
    with build_world(bowl_task, seed=0, debug_weld=True) as world:
        assert run_step(world, Step("pick", ("akita_black_bowl_1", "main_table"))).ok
        assert set(world.welds) == {"akita_black_bowl_1"}
        assert run_step(world, Step("place_on", ("akita_black_bowl_1", "plate_1"))).ok
        assert world.welds == {}
