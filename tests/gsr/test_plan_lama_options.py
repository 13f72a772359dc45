"""lama's ``LamaOptions.lifo`` and ``LamaOptions.disjunctive`` (issue 18, eighth pass).

``lifo`` runs the main search with h_add's last-in-first-out buckets (the dovetailed search takes
the other order) and leaves the relaxation's order as it found it; ``disjunctive`` is the landmark
graph the planner builds for ``lama``.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import pytest

import gsr.plan.api as plan_api
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import LAMA_FIRST, LamaOptions, lazy_lama
from gsr.validate import validate_plan

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def _task(folder: str, problem: str):
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    prob = load_problem(FIXTURES / folder / problem, domain)
    return domain, prob, ground_task(domain, prob)


@pytest.mark.parametrize("dovetail", [0, 2])
@pytest.mark.parametrize(
    "folder,problem", [("blocks", "probBLOCKS-9-2.pddl"), ("miconic-simpleadl", "s4-0.pddl")]
)
def test_lifo_option_is_the_relaxation_switched_beforehand(folder: str, problem: str, dovetail: int) -> None:
    """options.lifo on a FIFO relaxation searches exactly as a relaxation set to LIFO before the
    call, and hands the relaxation back in FIFO order."""
    domain, prob, task = _task(folder, problem)
    lm = Landmarks(task, disjunctive=True)
    options = LamaOptions(lifo=True, dovetail=dovetail)
    relax = Relaxation(task, unit=True)
    res = lazy_lama(task, relax, lm, time.perf_counter() + 60, options)
    assert relax.lifo is False
    preset = Relaxation(task, unit=True)
    preset.lifo = True
    same = lazy_lama(task, preset, lm, time.perf_counter() + 60, replace(options, lifo=False))
    assert preset.lifo is True
    assert res.status == same.status == "solved"
    assert (res.ops, res.expanded) == (same.ops, same.expanded)
    assert validate_plan(domain, prob, task.to_plan(res.ops)).valid


class _OneOrder(Relaxation):
    """A relaxation that, like numba's kernels, knows FIFO buckets only."""

    @property
    def lifo(self) -> bool:
        return False

    @lifo.setter
    def lifo(self, value: bool) -> None:
        if value:
            raise ValueError("one order only")


def test_lifo_option_keeps_a_relaxation_that_cannot_switch() -> None:
    domain, prob, task = _task("blocks", "probBLOCKS-9-2.pddl")
    relax = _OneOrder(task, unit=True)
    res = lazy_lama(task, relax, Landmarks(task), time.perf_counter() + 60, LamaOptions(lifo=True))
    assert res.status == "solved"
    assert validate_plan(domain, prob, task.to_plan(res.ops)).valid


@pytest.mark.parametrize("disjunctive", [False, True])
def test_planner_builds_the_landmark_graph_of_the_default(monkeypatch, disjunctive: bool) -> None:
    built: list[bool] = []

    class Recording(Landmarks):
        def __init__(self, task, *args, **kwargs) -> None:
            built.append(kwargs.get("disjunctive", False))
            super().__init__(task, *args, **kwargs)

    monkeypatch.setattr(plan_api, "Landmarks", Recording)
    monkeypatch.setattr(plan_api, "LAMA_FIRST", replace(LAMA_FIRST, disjunctive=disjunctive))
    domain = load_domain(FIXTURES / "gripper" / "domain.pddl")
    result = plan(domain, load_problem(FIXTURES / "gripper" / "prob06.pddl", domain), "lama", 60)
    assert result.solved
    assert built == [disjunctive]


def test_disjunctive_landmarks_can_leave_the_preferred_operators() -> None:
    """``lm_preferred_disjunctive=False``: only operators adding a ready single-fact landmark are
    landmark-preferred; gripper prob06 has disjunctive landmarks ("a ball in one of the grippers")."""
    domain, prob, task = _task("gripper", "prob06.pddl")
    lm = Landmarks(task, disjunctive=True)
    single = [k for k, facts in enumerate(lm.lm_facts) if len(facts) == 1]
    assert len(single) < len(lm.lm_facts)  # some landmarks are disjunctive
    single_mask = sum(1 << k for k in single)
    only_single = lm.single_fact_adds()
    assert only_single and all(m and not m & ~single_mask for m in only_single.values())
    assert all(lm.lm_add_mask[i] & single_mask == m for i, m in only_single.items())
    accepted = lm.accept(0, task.init)
    ops = task.applicable(task.init)
    _h, every = lm.value(accepted, task.init, ops)
    _h, fewer = lm.value(accepted, task.init, ops, only_single)
    assert set(fewer) <= set(every)
    assert any(not lm.lm_add_mask[i] & single_mask for i in every)  # an achiever of a disjunction only
    assert set(fewer) < set(every)
    for options in (
        LamaOptions(lm_preferred_disjunctive=False),
        LamaOptions(progression="past-future", lm_preferred_disjunctive=False),
    ):
        res = lazy_lama(task, Relaxation(task, unit=True), lm, time.perf_counter() + 60, options)
        assert res.status == "solved"
        assert validate_plan(domain, prob, task.to_plan(res.ops)).valid


def test_lama_takes_the_disjunctive_graph_where_the_landmarks_are_goals_only(
    monkeypatch, shared_data
) -> None:
    """transport-sat08 p01: GSR's graph is the goal facts alone, the disjunctive landmarks add some, so
    planner lama searches with GOALS_ONLY_LAMA on the disjunctive graph; gripper's graph has
    non-goal landmarks, so lama keeps LAMA_FIRST and the single-fact graph."""
    calls: list[tuple[LamaOptions, int]] = []
    search = plan_api.lazy_lama

    def recording(task, relax, landmarks, deadline, options=LAMA_FIRST, trace=None):
        calls.append((options, sum(len(f) > 1 for f in landmarks.lm_facts)))
        return search(task, relax, landmarks, deadline, options, trace)

    monkeypatch.setattr(plan_api, "lazy_lama", recording)
    folder = shared_data / "pddl" / "transport-sat08-strips"
    domain = load_domain(folder / "domain.pddl")
    problem = load_problem(folder / "p01.pddl", domain)
    assert Landmarks(ground_task(domain, problem)).goals_only()
    result = plan(domain, problem, "lama", 60)
    assert result.solved and validate_plan(domain, problem, result.plan).valid
    assert calls[-1][0] == plan_api.GOALS_ONLY_LAMA and calls[-1][1] > 0
    _domain, _prob, task = _task("gripper", "prob06.pddl")
    assert not Landmarks(task).goals_only()
    domain = load_domain(FIXTURES / "gripper" / "domain.pddl")
    assert plan(domain, load_problem(FIXTURES / "gripper" / "prob06.pddl", domain), "lama", 60).solved
    assert calls[-1] == (LAMA_FIRST, 0)
