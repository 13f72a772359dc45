"""Static disjunctions joined while listing bindings (gsr.plan.grounding.static_join) and the
one-alternative choices of the interning's DNF: the ground task is exactly what it is without them."""

from __future__ import annotations

import itertools
import random

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.pddl.model import FALSE
from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan import plan
from gsr.plan.grounding import ObjectsByType, grounding_tables
from gsr.plan.grounding import fixpoint as ground
from gsr.plan.grounding import static_join as sj
from gsr.plan.grounding.precondition import expand_dnf
from gsr.plan.grounding.simplify import Simplifier
from gsr.resources import load_builtin_domain

_ROADS = """
(define (domain roads)
  (:requirements :strips :typing :disjunctive-preconditions :existential-preconditions :negative-preconditions)
  (:types place truck)
  (:predicates (at ?t - truck ?p - place) (road ?a - place ?b - place) (ferry ?a - place ?b - place)
               (toll ?p - place) (paid ?t - truck))
  (:action drive
    :parameters (?t - truck ?from - place ?to - place)
    :precondition (and (at ?t ?from)
                       (or (road ?from ?to) (ferry ?to ?from)
                           (exists (?m - place) (and (road ?from ?m) (road ?m ?to)))))
    :effect (and (not (at ?t ?from)) (at ?t ?to)))
  (:action detour
    :parameters (?t - truck ?from - place ?to - place)
    :precondition (and (at ?t ?from) (paid ?t) (or (toll ?to) (not (road ?from ?to))))
    :effect (and (not (at ?t ?from)) (at ?t ?to)))
  (:action pay
    :parameters (?t - truck ?p - place)
    :precondition (and (at ?t ?p) (toll ?p))
    :effect (paid ?t)))
"""

_ROADS_PROBLEM = """
(define (problem r1) (:domain roads)
  (:objects a b c d e f - place t1 t2 - truck)
  (:init (at t1 a) (at t2 f) (road a b) (road b c) (ferry d c) (road c e) (toll c))
  (:goal (and (at t1 e) (paid t1))))
"""


def _fields(task):
    return (
        [(a.predicate, a.args) for a in task.atoms],
        [(o.name, o.args, o.cost, o.pre, o.neg, o.add, o.delete, o.cond) for o in task.ops],
        task.init,
        task.goals,
    )


def _without_joins(monkeypatch, domain, problem):
    monkeypatch.setattr(ground, "relation", lambda join, index: None)
    try:
        return ground.ground_task(domain, problem)
    finally:
        monkeypatch.undo()


def test_a_static_disjunction_becomes_a_relation_and_the_task_is_unchanged(monkeypatch) -> None:
    domain = parse_domain(_ROADS)
    problem = parse_problem(_ROADS_PROBLEM, domain=domain)
    tables = grounding_tables(domain)
    names = [s.name for s in tables.schemas]
    drive = names.index("drive")
    (join,) = tables.static_joins[drive]
    # detour's disjunction has a negated atom: tested per binding as before, never joined
    assert tables.static_joins[names.index("detour")] == ()
    index: dict[str, set[tuple[str, ...]]] = {}
    for a in problem.init:
        index.setdefault(a.predicate, set()).add(a.args)
    rel = sj.relation(join, index)
    # road, ferry backwards, and two roads through a middle place (the relation's order of
    # variables is the disjunction's sorted free variables: ?from, ?to)
    assert join[0].args == ("?from", "?to")
    assert rel == {("a", "b"), ("b", "c"), ("c", "d"), ("c", "e"), ("a", "c"), ("b", "e")}
    with_joins = ground.ground_task(domain, problem)
    assert _fields(with_joins) == _fields(_without_joins(monkeypatch, domain, problem))
    assert {o.args[1:] for o in with_joins.ops if o.name == "drive"} <= rel
    result = plan(domain, problem)
    assert result.solved, result.message


def test_a_relation_past_the_work_limit_falls_back_to_testing_per_binding(monkeypatch) -> None:
    domain = parse_domain(_ROADS)
    problem = parse_problem(_ROADS_PROBLEM, domain=domain)
    full = ground.ground_task(domain, problem)
    monkeypatch.setattr(sj, "WORK_LIMIT", 3)
    tables = grounding_tables(domain)
    join = tables.static_joins[[s.name for s in tables.schemas].index("drive")][0]
    index = {"road": {("a", "b"), ("b", "c"), ("c", "e")}, "ferry": {("d", "c")}}
    assert sj.relation(join, index) is None
    assert _fields(ground.ground_task(domain, problem)) == _fields(full)


@pytest.mark.parametrize("seed", [0, 5])
def test_push_relation_holds_every_pair_its_disjunction_allows(monkeypatch, seed) -> None:
    domain = load_builtin_domain("tabletop")
    name, graph, goal, _ = long_tabletop_task(seed)
    problem = problem_from_graph(graph, goal, name=name, domain=domain)
    tables = grounding_tables(domain)
    si = [s.name for s in tables.schemas].index("push")
    ((part, free),) = tables.static_narrow[si]
    (join,) = tables.static_joins[si]
    index: dict[str, set[tuple[str, ...]]] = {}
    for a in problem.init:
        index.setdefault(a.predicate, set()).add(a.args)
    rel = sj.relation(join, index)
    objects = ObjectsByType(domain, problem.all_objects(domain))
    simplify = Simplifier(objects, tables.fluent, problem.init)
    things = sorted(objects(("thing",)))
    holds = {
        pair
        for pair in itertools.product(things, repeat=2)
        if simplify(part, dict(zip(free, pair, strict=True))) is not FALSE
    }
    assert holds and holds <= rel
    assert _fields(ground.ground_task(domain, problem)) == _fields(
        _without_joins(monkeypatch, domain, problem)
    )


def _reference_dnf(lits, choices):
    """Every consistent pick of one alternative per choice with the literals, minimal ones only."""
    found = set()
    for pick in itertools.product(*choices):
        d = frozenset(lits).union(*pick)
        if not any(~x in d for x in d):
            found.add(d)
    return {d for d in found if not any(k < d for k in found)}


def test_expand_dnf_gives_the_minimal_consistent_picks() -> None:
    rng = random.Random(3)
    sizes = set()
    for _ in range(600):
        lits = [x if rng.random() < 0.6 else ~x for x in rng.sample(range(1, 9), rng.randrange(0, 3))]

        def conj():
            return frozenset(
                x if rng.random() < 0.6 else ~x for x in rng.sample(range(1, 9), rng.randrange(1, 3))
            )

        choices = [[conj() for _ in range(rng.randrange(1, 4))] for _ in range(rng.randrange(0, 4))]
        got = expand_dnf(lits, choices)
        assert len(got) == len(set(got))
        assert set(got) == _reference_dnf(lits, choices)
        assert [len(d) for d in got] == sorted(len(d) for d in got)
        sizes.add(len(got))
    assert {0, 1, 2} <= sizes  # contradictions, single disjuncts and real choices all came up
