"""The propose-check-repair loop with scripted models: repairs, modes, stops, garbage never executes."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.pddl.parser import parse_formula
from gsr.reason import FunctionBackend, solve
from gsr.semantics import goal_holds
from gsr.step import Goal

from .conftest import PICK, PLACE, Script


def test_steps_mode_repairs_after_diagnosis(graph, domain, box_goal):
    model = Script(
        ["no idea", "(pick red_cube1 blue_box)", "(pick red_cube1 table) +(holding red_cube1)", PICK, PLACE]
    )
    result = solve(graph, box_goal.text, model, goal=box_goal, domain=domain)
    assert result.success and result.status == "solved"
    assert [s.step.action for s in result.steps] == ["pick", "place_in"]
    first = result.steps[0]
    assert len(first.rejected) == 3 and result.repairs == 1 and result.rejections == 3
    assert "cannot parse the step" in first.rejected[0].error and "reply:1:1" in first.rejected[0].error
    assert not first.rejected[1].diagnosis.ok  # wrong source: precondition
    assert "missing delete effect (not (hand_empty))" in first.rejected[2].diagnosis.message
    # each diagnosis went back to the model in the next prompt
    assert "rejected: cannot parse" in model.prompts[1].user
    assert "precondition (or (on red_cube1 blue_box)" in model.prompts[2].user
    assert "missing delete effect" in model.prompts[3].user
    # the accepted pick advanced the graph: the next prompt shows it held, and the history
    assert "red_cube1 (cube, red) [held]" in model.prompts[4].user
    assert "Steps so far:\n" + PICK in model.prompts[4].user
    assert goal_holds(domain, box_goal, state_from_graph(result.final_graph, domain))
    assert len(result.transcript) == 5 and result.transcript[0].response == "no idea"


def test_stuck_after_k_repairs_and_nothing_executes(graph, domain, box_goal):
    model = Script(["(place_in red_cube1 blue_box)"] * 10)
    result = solve(graph, "x", model, goal=box_goal, domain=domain, max_repairs=2)
    assert result.status == "stuck" and not result.success
    assert result.steps == [] and result.model_calls == 3
    assert len(result.unrepaired) == 1 and len(result.unrepaired[0]) == 3
    assert result.final_graph == graph


def test_hybrid_planner_takes_over_when_stuck(graph, domain, box_goal):
    model = Script([PICK, "garbage", "garbage"])
    result = solve(graph, "x", model, mode="hybrid", goal=box_goal, domain=domain, max_repairs=1)
    assert result.success and result.planner_takeovers == 1
    assert [s.source for s in result.steps] == ["model", "planner"]


def test_hybrid_takes_over_on_a_revisited_state(graph, domain, box_goal):
    undo = "(place_on red_cube1 table) +(on red_cube1 table) +(hand_empty) -(holding red_cube1)"
    result = solve(graph, "x", Script([PICK, undo]), mode="hybrid", goal=box_goal, domain=domain)
    assert result.success and result.planner_takeovers == 1
    assert [s.source for s in result.steps][:2] == ["model", "model"]


def test_goal_mode_repairs_a_bad_goal_then_plans(graph, domain):
    model = Script(["(in red_cube blue_box)", "(in red_cube1 red_cube1)", "(in red_cube1 blue_box)"])
    result = solve(graph, "put the red cube in the blue box", model, mode="goal", domain=domain)
    assert result.success and result.goal_source == "model"
    assert "unknown object red_cube (did you mean red_cube1" in result.goal_attempts[0].error
    assert "planner cannot reach" in result.goal_attempts[1].error
    assert "rejected: unknown object red_cube" in model.prompts[1].user
    assert all(s.source == "planner" for s in result.steps) and result.repairs == 1


def test_goal_mode_gives_up(graph, domain):
    result = solve(graph, "x", Script(["???"] * 5), mode="goal", domain=domain, max_repairs=1)
    assert result.status == "no_goal" and result.steps == []


def test_done_is_checked_against_the_goal(graph, domain, box_goal):
    model = Script(["(done)", PICK, PLACE])
    result = solve(graph, "x", model, goal=box_goal, domain=domain)
    assert result.success
    assert (
        "the goal does not hold yet: goal (in red_cube1 blue_box) is false"
        in result.steps[0].rejected[0].error
    )


def test_step_limit(graph, domain, box_goal):
    result = solve(graph, "x", Script([PICK, PLACE]), goal=box_goal, domain=domain, max_steps=1)
    assert result.status == "step_limit" and len(result.steps) == 1


def test_require_effects(graph, domain, box_goal):
    model = Script(["(pick red_cube1 table)", PICK, PLACE])
    result = solve(graph, "x", model, goal=box_goal, domain=domain, require_effects=True)
    assert result.success and "claims no effects" in result.steps[0].rejected[0].error


def test_backend_crash_is_reported(graph, domain, box_goal):
    def broken(text: str) -> str:
        raise RuntimeError("CUDA out of memory")

    result = solve(graph, "x", FunctionBackend(broken), goal=box_goal, domain=domain)
    assert result.status == "backend_error" and "CUDA out of memory" in result.message


def test_grounder_backend_all_modes(graph, domain, box_goal):
    for mode in ("steps", "goal", "hybrid"):
        result = solve(graph, "x", "grounder", mode=mode, goal=box_goal, domain=domain)
        assert result.success, (mode, result.message)
        assert [s.step.action for s in result.steps] == ["pick", "place_in"]


def test_grounder_backend_impossible_goal(graph, domain):
    goal = Goal(parse_formula("(in red_cube1 red_cube1)"))
    assert solve(graph, "x", "grounder", goal=goal, domain=domain).status == "unsolvable"
    assert solve(graph, "x", "grounder", mode="goal", goal=goal, domain=domain).status == "unsolvable"


def test_bad_arguments(graph):
    with pytest.raises(GSRError, match="unknown mode"):
        solve(graph, "x", "grounder", mode="dream")
    with pytest.raises(GSRError, match="unknown backend"):
        solve(graph, "x", "gpt")


@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(st.lists(st.text(max_size=80), min_size=1, max_size=4))
def test_garbage_never_crashes_and_never_executes(graph, domain, box_goal, replies):
    result = solve(graph, "x", Script(replies), goal=box_goal, domain=domain, max_repairs=len(replies) - 1)
    assert result.status == "stuck"
    assert result.steps == []


def test_json_answers_are_accepted(graph, domain, box_goal):
    pick = '{"action": "pick", "args": ["red_cube1", "table"], "add": ["(holding red_cube1)"], "delete": ["(hand_empty)", "(on red_cube1 table)"]}'
    result = solve(graph, "x", Script([pick, "```\n" + PLACE + "\n```"]), goal=box_goal, domain=domain)
    assert result.success and result.rejections == 0


def test_a_plan_proposer_is_asked_once_and_no_prompt_is_built(monkeypatch) -> None:
    """The grounder backend proposes Step objects: a long solve makes one planner call and no prompt."""
    from gsr.benchmarks.suites import get_suite

    import gsr.plan.api as plan_api
    import gsr.reason.loop as loop

    task = next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id.endswith("sod_simple_00"))
    calls = {"plan": 0, "prompt": 0}
    real_plan = plan_api.plan_graph

    def counting_plan(*a, **k):
        calls["plan"] += 1
        return real_plan(*a, **k)

    def no_prompt(*a, **k):
        calls["prompt"] += 1
        raise AssertionError("a prompt was built for the grounder backend")

    monkeypatch.setattr(plan_api, "plan_graph", counting_plan)
    monkeypatch.setattr(loop, "build_prompt", no_prompt)
    result = solve(task.initial, task.instruction)
    assert result.status == "solved" and len(result.steps) >= 6
    assert calls == {"plan": 1, "prompt": 0}


def test_a_rejected_proposal_is_diagnosed_and_the_proposer_asked_again(graph, domain, box_goal) -> None:
    from gsr.reason.step_format import parse_first_step

    class Proposer(FunctionBackend):
        def __init__(self, plans):
            super().__init__(lambda text: "(done)")
            self.plans, self.asked = list(plans), 0

        def propose_plan(self, domain, graph, goal):
            self.asked += 1
            return [parse_first_step(line) for line in self.plans.pop(0)]

    bad, good = ["(pick red_cube1 blue_box)"], [PICK.split(" +")[0], PLACE.split(" +")[0]]
    proposer = Proposer([bad, good])
    result = solve(graph, box_goal.text, proposer, goal=box_goal, domain=domain)
    assert result.status == "solved" and proposer.asked == 2
    assert [s.step.action for s in result.steps] == ["pick", "place_in"]
    assert not result.steps[0].rejected[0].diagnosis.ok  # the bad step was checked, not executed
    stuck = solve(graph, box_goal.text, Proposer([bad] * 5), goal=box_goal, domain=domain, max_repairs=2)
    assert stuck.status == "stuck" and not stuck.steps
