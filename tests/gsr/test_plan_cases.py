"""Case-analysis preconditions (a top-level disjunction of conjunctions with equalities) are split
into one schema per case with the equalities joined (gsr.plan.grounding.normalize.split_cases)."""

from __future__ import annotations

import itertools

import pytest

from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan import ground_task, plan
from gsr.plan.grounding import fixpoint as ground_module
from gsr.plan.grounding.normalize import EQUALS, normalize_action, split_cases
from gsr.validate import validate_plan

GRID = """
(define (domain grid-walk)
  (:requirements :adl :typing)
  (:types coord dir - object)
  (:constants up down left right - dir)
  (:predicates (at ?x ?y - coord) (inc ?a ?b - coord) (free ?x ?y - coord) (facing ?d - dir))
  (:action step
    :parameters (?x ?y ?x2 ?y2 - coord ?d - dir)
    :precondition (and (at ?x ?y) (facing ?d) (free ?x2 ?y2)
      (or (and (= ?d up) (= ?x ?x2) (inc ?y ?y2))
          (and (= ?d down) (= ?x ?x2) (inc ?y2 ?y))
          (and (= ?d left) (= ?y ?y2) (inc ?x2 ?x))
          (and (= ?d right) (= ?y ?y2) (inc ?x ?x2))))
    :effect (and (not (at ?x ?y)) (at ?x2 ?y2) (free ?x ?y) (not (free ?x2 ?y2))))
  (:action slide
    :parameters (?x ?y ?x2 ?y2 - coord)
    :precondition (and (at ?x ?y) (free ?x2 ?y2) (= ?y ?y2) (inc ?x ?x2) (facing right))
    :effect (and (not (at ?x ?y)) (at ?x2 ?y2) (free ?x ?y) (not (free ?x2 ?y2))))
  (:action turn
    :parameters (?d ?e - dir)
    :precondition (and (facing ?d) (not (= ?d ?e)))
    :effect (and (not (facing ?d)) (facing ?e))))
"""


def _problem(n: int) -> str:
    cs = [f"c{i}" for i in range(n)]
    init = [f"(inc {a} {b})" for a, b in itertools.pairwise(cs)]
    init += [f"(free {x} {y})" for x in cs for y in cs if (x, y) != ("c0", "c0")]
    init += ["(at c0 c0)", "(facing up)"]
    goal = f"(at c{n - 1} c{n - 2})"
    return f"(define (problem walk) (:domain grid-walk) (:objects {' '.join(cs)} - coord) (:init {' '.join(init)}) (:goal {goal}))"


def test_a_case_analysis_splits_into_one_schema_per_case_with_equalities_as_join_atoms() -> None:
    domain = parse_domain(GRID)
    cases = split_cases(normalize_action(domain.actions["step"]))
    assert len(cases) == 4
    for case in cases:
        preds = [a.predicate for a in case.join]
        assert preds.count(EQUALS) == 2 and "inc" in preds
    # no case analysis: one schema; a top-level equality joins too
    assert len(split_cases(normalize_action(domain.actions["turn"]))) == 1
    (slide,) = split_cases(normalize_action(domain.actions["slide"]))
    assert [a.args for a in slide.join if a.predicate == EQUALS] == [("?y", "?y2")]


def test_split_cases_ground_the_same_operators_and_plan_validly(monkeypatch: pytest.MonkeyPatch) -> None:
    domain = parse_domain(GRID)
    problem = parse_problem(_problem(6), domain)
    split = ground_task(domain, problem)
    monkeypatch.setattr(ground_module, "split_cases", lambda schema: [schema])
    unsplit = parse_domain(GRID)  # a new domain object: its grounding tables are compiled afresh
    whole = ground_task(unsplit, parse_problem(_problem(6), unsplit))
    assert sorted((o.name, o.args) for o in split.ops) == sorted((o.name, o.args) for o in whole.ops)
    assert split.atoms == whole.atoms
    monkeypatch.undo()
    result = plan(domain, problem, planner="lama", timeout=60)
    assert result.status == "solved"
    assert validate_plan(domain, problem, result.plan).valid
