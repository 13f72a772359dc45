"""lama's dovetailed second search (``LamaOptions.dovetail``, issue 18's sixth pass).

A second lazy search whose h_add settles equally cheap facts in the other bucket order takes turns
with the main one, its share of the turns shrinking as sqrt(share * main turns); the first search
to finish gives the result.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import replace
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import LAMA_FIRST, dovetail, lazy_lama
from gsr.validate import validate_plan

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def _steps(name: str, n: int, log: list):
    for _ in range(n):
        log.append(name)
        yield


def test_dovetail_turns_shrink_as_sqrt_of_the_main_turns() -> None:
    log: list[str] = []
    switches: list[str] = []
    first = dovetail(
        _steps("m", 1000, log),
        _steps("o", 10**6, log),
        4,
        lambda: switches.append("to m"),
        lambda: switches.append("to o"),
    )
    assert first == 0  # the main generator ran out first
    assert log[:7] == ["m", "o", "o", "m", "o", "m", "o"]  # t * t < 4 * m
    turns_other = log.count("o")
    assert log.count("m") == 1000
    assert (turns_other - 1) ** 2 < 4 * 1000 <= turns_other**2
    # switches only where the turn changes hands
    changes = sum(1 for a, b in itertools.pairwise(log) if a != b)
    assert len(switches) == changes + 1


def test_dovetail_reports_the_other_and_drops_it_when_it_cannot_switch() -> None:
    log: list[str] = []
    assert dovetail(_steps("m", 100, log), _steps("o", 3, log), 4, lambda: None, lambda: None) == 1
    assert log.count("o") == 3

    def refuse() -> None:
        raise ValueError("numba kernels: one order only")

    log.clear()
    assert dovetail(_steps("m", 50, log), _steps("o", 50, log), 4, lambda: None, refuse) == 0
    assert log == ["m"] * 50


@pytest.mark.parametrize(
    "folder,problem",
    [("blocks", "probBLOCKS-9-2.pddl"), ("gripper", "prob06.pddl"), ("miconic-simpleadl", "s4-0.pddl")],
)
def test_dovetailed_lama_plans_are_valid_and_restore_the_order(folder: str, problem: str) -> None:
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    prob = load_problem(FIXTURES / folder / problem, domain)
    task = ground_task(domain, prob)
    relax = Relaxation(task, unit=True)
    assert LAMA_FIRST.dovetail > 0
    res = lazy_lama(task, relax, Landmarks(task), time.perf_counter() + 60)
    assert res.status == "solved"
    assert validate_plan(domain, prob, task.to_plan(res.ops)).valid
    assert relax.lifo is False  # the main search's order is back
    alone = lazy_lama(task, relax, Landmarks(task), time.perf_counter() + 60, replace(LAMA_FIRST, dovetail=0))
    assert alone.status == "solved"
    # below one turn of CLOCK_EVERY expansions the main search has not yet handed over
    if alone.expanded < 64:
        assert res.ops == alone.ops


def test_dovetail_solves_tidybot_p01(shared_data) -> None:
    """GSR's bucket order alone finds no plan for tidybot-sat11 p01 in 60 s CPU (fifth pass); the
    other order solves it in 867 expansions, so the dovetailed pair does within a few thousand."""
    folder = shared_data / "pddl" / "tidybot-sat11-strips"
    domain = load_domain(folder / "domain.pddl")
    prob = load_problem(folder / "p01.pddl", domain)
    task = ground_task(domain, prob)
    res = lazy_lama(task, Relaxation(task, unit=True), Landmarks(task), time.perf_counter() + 120)
    assert res.status == "solved"
    assert res.expanded < 10_000
    assert validate_plan(domain, prob, task.to_plan(res.ops)).valid
