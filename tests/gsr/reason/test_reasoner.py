"""The typed loop settings, the str-valued statuses and the closed-loop Reasoner (reset, then step)."""

from __future__ import annotations

import dataclasses
import json

import pytest

import gsr.plan.api as plan_api
from gsr.check import check_step
from gsr.errors import GSRError
from gsr.facts import graph_with_state, state_from_graph
from gsr.reason import STATUSES, Reasoner, SolveOptions, Status, solve
from gsr.semantics import goal_holds
from gsr.step import Step


def test_options_are_frozen_and_checked() -> None:
    options = SolveOptions(mode="hybrid", max_steps=5)
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.mode = "goal"  # type: ignore[misc]
    with pytest.raises(GSRError, match="unknown mode"):
        SolveOptions(mode="dream")
    with pytest.raises(GSRError, match=">= 0"):
        SolveOptions(max_repairs=-1)


def test_statuses_read_as_their_strings(graph, domain, box_goal) -> None:
    result = solve(graph, "x", domain=domain, goal=box_goal)
    assert result.status is Status.SOLVED and result.status == "solved"
    assert f"{result.status}" == "solved" and json.dumps(result.status) == '"solved"'
    assert type(result.to_dict()["status"]) is str
    assert tuple(str(s) for s in Status) == STATUSES and "backend_error" in STATUSES


def test_options_object_equals_keywords(graph, domain, box_goal) -> None:
    by_keywords = solve(graph, "x", domain=domain, goal=box_goal, mode="goal", max_steps=1)
    by_options = solve(
        graph, "x", domain=domain, goal=box_goal, options=SolveOptions(mode="goal", max_steps=1)
    )
    assert by_keywords.status == by_options.status == Status.STEP_LIMIT
    assert [s.step for s in by_keywords.steps] == [s.step for s in by_options.steps]


def _counting_planner(monkeypatch) -> dict[str, int]:
    calls = {"plan": 0}
    real = plan_api.plan_graph

    def counting(*a, **k):
        calls["plan"] += 1
        return real(*a, **k)

    monkeypatch.setattr(plan_api, "plan_graph", counting)
    return calls


def _run(reasoner: Reasoner, graph, domain, skip: int | None = None, limit: int = 20):
    """Execute the reasoner's steps on the symbolic state; step number ``skip`` 'fails' (no change)."""
    state = state_from_graph(graph, domain)
    done = []
    for k in range(limit):
        step = reasoner.step(graph_with_state(graph, state), None)
        if step is None:
            return state, done
        diagnosis = check_step(domain, state, step)
        assert diagnosis.ok, diagnosis.message  # the reasoner only hands out steps valid for the graph shown
        done.append(step)
        if k != skip:
            state = diagnosis.next_state
    raise AssertionError("the reasoner never finished")


def test_step_follows_the_plan_while_the_graph_is_as_expected(graph, domain, box_goal, monkeypatch) -> None:
    calls = _counting_planner(monkeypatch)
    reasoner = Reasoner("grounder", domain)
    first = reasoner.reset(graph, "put the red cube in the blue box")
    state, done = _run(reasoner, graph, domain)
    assert goal_holds(domain, reasoner.goal, state)
    assert done == [s.step for s in first.steps] and len(done) >= 2
    assert calls["plan"] == 1 and reasoner.replans == 0
    assert reasoner.step(graph_with_state(graph, state)) is None  # nothing left once the goal holds


def test_step_replans_when_the_graph_diverges(graph, domain, monkeypatch) -> None:
    calls = _counting_planner(monkeypatch)
    reasoner = Reasoner("grounder", domain)
    first = reasoner.reset(graph, "put the red cube in the blue box")
    state, done = _run(reasoner, graph, domain, skip=0)  # the first step 'fails' in the world
    assert reasoner.replans == 1 and calls["plan"] == 2
    assert done[0] == done[1] == first.steps[0].step  # asked again from the graph it was shown
    assert goal_holds(domain, reasoner.goal, state)  # and still reached the goal


def test_step_replans_after_a_rejected_step(graph, domain) -> None:
    reasoner = Reasoner("grounder", domain)
    reasoner.reset(graph, "put the red cube in the blue box")
    reasoner.step(graph)
    state = state_from_graph(graph, domain)
    rejected = check_step(domain, state, Step("place_in", ("red_cube1", "blue_box")))
    assert not rejected.ok
    again = reasoner.step(graph, rejected)  # same graph, but the runner rejected the step it was given
    assert reasoner.replans == 1 and check_step(domain, state, again).ok


def test_step_needs_reset(graph, domain) -> None:
    with pytest.raises(GSRError, match="reset"):
        Reasoner("grounder", domain).step(graph)
