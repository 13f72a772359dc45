"""Interning by (predicate, args) keys: the general DNF path, the goal, the initial state and effect
conditions as key literals (gsr.plan.grounding.intern / effects)."""

from __future__ import annotations

import itertools

import pytest

import gsr.plan.grounding.intern as intern
from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan.grounding import ObjectsByType, ground_goal, ground_task, grounding_tables
from gsr.plan.grounding.simplify import Simplifier

# ``deep``'s precondition nests a disjunction inside a conjunction inside a disjunction: neither the
# compiled path nor fast_dnf take it, so interning goes through id_dnf (the general path). ``spoil``
# makes (d ?x) fluent (not folded away as static) but never reached.
NESTED = """
(define (domain nested)
  (:requirements :adl :typing)
  (:types box)
  (:predicates (a ?x - box) (b ?x - box) (c ?x - box) (d ?x - box) (done ?x - box) (ready) (never))
  (:action spoil
    :parameters (?x - box)
    :precondition (never)
    :effect (and (d ?x) (not (never))))
  (:action make
    :parameters (?x - box)
    :precondition (ready)
    :effect (and (a ?x) (c ?x)))
  (:action deep
    :parameters (?x - box)
    :precondition (or (and (a ?x) (or (b ?x) (c ?x))) (d ?x))
    :effect (and (done ?x) (when (and (a ?x) (not (b ?x))) (b ?x)))))
"""

PROBLEM = """
(define (problem nested-1) (:domain nested)
  (:objects p q - box)
  (:init (ready) (a q))
  (:goal (and (done p) (or (done q) (not (b q))))))
"""


def _task():
    domain = parse_domain(NESTED)
    return domain, parse_problem(PROBLEM, domain)


def test_nested_precondition_goes_through_the_general_dnf(monkeypatch: pytest.MonkeyPatch) -> None:
    calls = []
    real = intern.id_dnf

    def spy(formula, reached, ids):
        calls.append(reached)
        return real(formula, reached, ids)

    monkeypatch.setattr(intern, "id_dnf", spy)
    domain, problem = _task()
    task = ground_task(domain, problem)
    assert calls, "the nested precondition should need the general path"
    # The general path prunes by reached Atoms: every reached key's Atom, the initial ones included.
    assert {str(a) for a in calls[0]} >= {"(ready)", "(a q)", "(a p)", "(c p)"}
    names = {str(a): i for i, a in enumerate(task.atoms)}
    deep = {o.args[0]: [] for o in task.ops if o.name == "deep"}
    for o in task.ops:
        if o.name == "deep":
            deep[o.args[0]].append(tuple(sorted(str(task.atoms[i]) for i in o.pre)))
    # (d ?x) is never reached and (b ?x) only by deep's own effect: the minimal DNF over reached atoms.
    for x in ("p", "q"):
        assert sorted(deep[x]) == sorted([(f"(a {x})", f"(b {x})"), (f"(a {x})", f"(c {x})")]), deep
    assert "(d p)" not in names


def test_goal_and_initial_state_by_key_equal_the_atom_interface() -> None:
    domain, problem = _task()
    task = ground_task(domain, problem)
    ids = {a: i for i, a in enumerate(task.atoms)}
    fluent = grounding_tables(domain).fluent
    simplify = Simplifier(ObjectsByType(domain, problem.all_objects(domain)), fluent, problem.init)
    # ground_goal (Atom ids, the public interface) and the interning's own goal agree.
    assert ground_goal(domain, problem, problem.goal, ids, fluent, simplify) == task.goals
    assert ground_goal(domain, problem, problem.goal, ids, fluent) == task.goals
    init = {str(task.atoms[i]) for i in range(len(task.atoms)) if task.init >> i & 1}
    assert init == {"(a q)"}  # (ready) is static: compiled away
    # The initial atoms keep their own objects in task.atoms.
    by_name = {str(a): a for a in problem.init}
    assert any(a is by_name["(a q)"] for a in task.atoms)


def test_conditional_effect_conditions_are_key_literals() -> None:
    domain, problem = _task()
    task = ground_task(domain, problem)
    text = {str(task.atoms[i]): i for i in range(len(task.atoms))}
    for o in task.ops:
        if o.name == "deep" and o.cond:
            # (when (and (a ?x) (not (b ?x))) (b ?x)): (a ?x) is in every deep's precondition, so
            # the condition left is (not (b ?x)) or the effect is unconditional.
            for cp, cn, add, _ in o.cond:
                assert text[f"(a {o.args[0]})"] not in cp
                assert cn == (text[f"(b {o.args[0]})"],) and add == (text[f"(b {o.args[0]})"],)


def test_ground_literal_keys_equal_ground_literals_as_keys() -> None:
    domain, problem = _task()
    fluent = grounding_tables(domain).fluent
    objects = ObjectsByType(domain, problem.all_objects(domain))
    simplify = Simplifier(objects, fluent, problem.init)
    from gsr.pddl.model import Atom

    literals_pool = [
        (Atom("a", ("?x",)), True),
        (Atom("b", ("?x",)), False),
        (Atom("ready", ()), True),
        (Atom("a", ("?x",)), False),
    ]
    checked = 0
    for n in range(1, 4):
        for lits in itertools.permutations(literals_pool, n):
            for x in objects(("box",)):
                atoms = simplify.ground_literals(tuple(lits), {"?x": x})
                keys = simplify.ground_literal_keys(tuple(lits), {"?x": x})
                if atoms is None:
                    assert keys is None
                else:
                    assert keys == frozenset(((a.predicate, a.args), pos) for a, pos in atoms)
                checked += 1
    assert checked > 50
