"""The type-based queue of lama (``LamaOptions.type_based``, Xie et al. 2014; issue 18's sixth pass)."""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import LAMA_FIRST, TypeBuckets, lazy_lama
from gsr.validate import validate_plan

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def test_type_buckets_pop_every_entry_once_and_buckets_uniformly() -> None:
    q = TypeBuckets(n_ops=10, seed=3)
    q.push((1, 0), 0, [1, 2, 3])
    q.push((2, 1), 1, range(10))  # one big bucket
    q.push((5, 2), 7, [9])  # one single-entry bucket
    q.push((1, 0), 2, [4])  # joins the first bucket
    popped = []
    while q:
        popped.append(q.pop())
    expected = [(0, 1), (0, 2), (0, 3), (2, 4), (7, 9)] + [(1, op) for op in range(10)]
    assert sorted(popped) == sorted(expected)
    # a bucket is picked uniformly, not by its size: a lone entry beside 98 others comes first ~1/2
    firsts = Counter()
    for seed in range(300):
        q = TypeBuckets(n_ops=100, seed=seed)
        q.push((0,), 0, range(98))
        q.push((1,), 1, [99])
        firsts[q.pop() == (1, 99)] += 1
    assert 110 < firsts[True] < 190  # ~1/2, where popping by entry would give ~1/99


@pytest.mark.parametrize(
    "folder,problem",
    [("blocks", "probBLOCKS-9-2.pddl"), ("gripper", "prob06.pddl"), ("miconic-simpleadl", "s4-0.pddl")],
)
def test_type_based_lama_finds_valid_plans_and_repeats(folder: str, problem: str) -> None:
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    prob = load_problem(FIXTURES / folder / problem, domain)
    task = ground_task(domain, prob)
    options = replace(LAMA_FIRST, type_based=True)
    runs = [
        lazy_lama(task, Relaxation(task, unit=True), Landmarks(task), time.perf_counter() + 60, options)
        for _ in range(2)
    ]
    assert runs[0].status == "solved"
    assert validate_plan(domain, prob, task.to_plan(runs[0].ops)).valid
    assert runs[0].ops == runs[1].ops and runs[0].expanded == runs[1].expanded  # seeded
