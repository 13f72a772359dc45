"""The grounding fixpoint indexes atoms by argument only for the predicates the join looks up
(issue 18, seventh pass): the same tasks as with every atom indexed."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

from gsr.benchmarks.bench_planner import long_tabletop_task

import gsr.plan.grounding.fixpoint as fixpoint
from gsr.facts import problem_from_graph
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task, grounding_tables
from gsr.resources import load_builtin_domain

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def _fields(task):
    return (task.atoms, task.ops, task.init, task.goals, task.axioms)


def test_joined_predicates_of_the_tabletop_domain() -> None:
    joined = grounding_tables(load_builtin_domain("tabletop")).joined
    assert {"on", "in", "holding", "movable"} <= joined
    assert not {"cube_count", "next", "has_color"} & joined  # only tested, never joined


def test_indexing_only_joined_predicates_grounds_the_same_tasks(monkeypatch) -> None:
    cases = []
    for seed in (1, 4):
        name, graph, goal, _ = long_tabletop_task(seed)
        domain = load_builtin_domain("tabletop")
        cases.append((domain, problem_from_graph(graph, goal, name=name, domain=domain)))
    for folder, problem in (("miconic-simpleadl", "s4-0.pddl"), ("blocks", "probBLOCKS-6-0.pddl")):
        domain = load_domain(FIXTURES / folder / "domain.pddl")
        cases.append((domain, load_problem(FIXTURES / folder / problem, domain)))
    expected = [_fields(ground_task(d, p)) for d, p in cases]
    real = fixpoint.grounding_tables

    class Every(frozenset):
        def __contains__(self, item) -> bool:
            return True

    # Every predicate counted as joined: every atom indexed by argument, as before.
    monkeypatch.setattr(fixpoint, "grounding_tables", lambda d: dataclasses.replace(real(d), joined=Every()))
    for (domain, problem), want in zip(cases, expected, strict=True):
        assert _fields(ground_task(copy.copy(domain), problem)) == want
