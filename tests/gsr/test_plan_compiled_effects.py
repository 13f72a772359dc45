"""The compiled per-schema effects (gsr.plan.grounding.compiled_effects) build exactly the effect
blocks, deferred groups and queued add effects of the interpreted path, in the same order."""

from __future__ import annotations

import dataclasses

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan import plan
from gsr.plan.grounding import fixpoint as ground
from gsr.plan.grounding import grounding_tables
from gsr.plan.grounding.effects import effect_instances, ground_effects, new_adds
from gsr.plan.grounding.simplify import ObjectsByType, Simplifier
from gsr.resources import load_builtin_domain

_DOMAIN = """
(define (domain fx)
  (:requirements :strips :typing :conditional-effects :negative-preconditions)
  (:types obj)
  (:constants home - obj)
  (:predicates (at ?x - obj) (held ?x - obj) (lit ?x - obj) (near ?x - obj ?y - obj) (free) (seen ?x - obj))
  (:action take
    :parameters (?x - obj)
    :precondition (and (at ?x) (free))
    :effect (and (held ?x) (not (at ?x)) (not (free)) (seen home)
                 (forall (?y - obj) (when (and (near ?x ?y) (lit ?y)) (seen ?y)))
                 (when (lit ?x) (seen ?x))))
  (:action drop
    :parameters (?x - obj)
    :precondition (held ?x)
    :effect (and (at home) (free) (not (held ?x)) (lit ?x))))
"""

_PROBLEM = """
(define (problem fx1) (:domain fx)
  (:objects a b c - obj)
  (:init (at a) (at b) (free) (near a b) (near b c) (lit c))
  (:goal (and (seen b) (seen c) (seen home))))
"""


def _checked_fires(request, domain) -> list[int]:
    """Make every compiled fire also run the interpreted path on a copy and compare (until the
    test ends); returns a list that counts the comparisons."""
    tables = grounding_tables(domain)
    checked: list[int] = []
    original = list(tables.fires)
    request.addfinalizer(lambda: tables.fires.__setitem__(slice(None), original))
    for si, fire in enumerate(original):

        def both(v, simplify, reached, deferred, memo, pending, fire=fire, si=si):
            twin = dataclasses.replace(v)
            d0, p0 = len(deferred), len(pending)
            fire(v, simplify, reached, deferred, memo, pending)
            deferred2, pending2 = [], []
            ground_effects(twin, tables.groups[si], simplify, reached, deferred2, memo)
            new_adds(twin.effects, reached, pending2)
            assert v.effects == twin.effects
            assert pending[p0:] == pending2
            assert [(g, b, base) for _v, g, b, base in deferred[d0:]] == [
                (g, b, base) for _v, g, b, base in deferred2
            ]
            checked.append(si)

        tables.fires[si] = both
    return checked


def test_compiled_effects_equal_the_interpreted_ones(monkeypatch, request) -> None:
    domain = parse_domain(_DOMAIN)
    problem = parse_problem(_PROBLEM, domain=domain)
    monkeypatch.setattr(ground, "COMPILED", True)
    checked = _checked_fires(request, domain)
    compiled = ground.ground_task(domain, problem)
    assert len(set(checked)) == 2  # both schemas fired through the compiled effects
    monkeypatch.setattr(ground, "COMPILED", False)
    general = ground.ground_task(domain, problem)
    assert [(o.name, o.args, o.pre, o.neg, o.add, o.delete, o.cond) for o in compiled.ops] == [
        (o.name, o.args, o.pre, o.neg, o.add, o.delete, o.cond) for o in general.ops
    ]
    assert any(o.cond for o in compiled.ops)  # the conditional effects survived
    monkeypatch.setattr(ground, "COMPILED", True)
    result = plan(domain, problem)
    assert result.solved, result.message


def test_compiled_effects_inline_unconditional_literals() -> None:
    tables = grounding_tables(parse_domain(_DOMAIN))
    take = next(f for s, f in zip(tables.schemas, tables.fires, strict=True) if s.name == "take")
    assert "('seen', ('home',))" in take.source  # a constant, as written
    assert "group_effects(" in take.source  # the conditional groups: interpreted


@pytest.mark.parametrize("seed", [0, 5])
def test_compiled_tabletop_effects_equal_the_interpreted_ones(monkeypatch, request, seed) -> None:
    domain = load_builtin_domain("tabletop")
    name, graph, goal, _ = long_tabletop_task(seed)
    problem = problem_from_graph(graph, goal, name=name, domain=domain)
    monkeypatch.setattr(ground, "COMPILED", True)
    checked = _checked_fires(request, domain)
    task = ground.ground_task(domain, problem)
    assert len(checked) > 50 and len(task.ops) > 50


def test_effect_instances_are_joined_once_per_guard_value_with_the_same_result() -> None:
    domain = load_builtin_domain("tabletop")
    name, graph, goal, _ = long_tabletop_task(3)
    problem = problem_from_graph(graph, goal, name=name, domain=domain)
    tables = grounding_tables(domain)
    simplify = Simplifier(
        ObjectsByType(domain, problem.all_objects(domain)), tables.fluent, set(problem.init)
    )
    si = next(k for k, s in enumerate(tables.schemas) if s.name == "pick")
    group = next(g for g in tables.groups[si] if g[0])  # the cube counting: (next ?n ?m), (counted ?o)
    objects = sorted(problem.all_objects(domain))
    memo: dict = {}
    nonempty = 0
    for o in objects:
        for c in objects[:4]:
            binding = {"?o": o, "?from": c, "?h": "x"}
            expected = list(simplify.instances(group[0], group[2], binding))
            assert effect_instances(group, binding, simplify, memo) == expected
            nonempty += bool(expected)
    assert nonempty >= 4  # some object is counted: the (next ?n ?m) pairs were joined
    assert len(memo) == len({o for o in objects})  # one join per value of ?o, not per container
