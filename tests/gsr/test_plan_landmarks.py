"""RHW-style landmarks: complement facts ("not a") and disjunctive landmarks, and their use in lama.

A box stands on the goal cell of another box (a negative precondition, ``(not (occupied c))``,
must be made true first) and the goal cell opens with either of two keys (a disjunctive landmark,
``(have k1) | (have k2)``). Without complement and disjunctive landmarks neither is found.
"""

from __future__ import annotations

import pytest

from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan import plan
from gsr.plan.grounding import ground_task
from gsr.plan.landmarks import Landmarks
from gsr.validate import validate_plan

DOMAIN = """
(define (domain cells) (:requirements :typing :negative-preconditions)
 (:types cell box key)
 (:predicates (at ?b - box ?c - cell) (occupied ?c - cell) (holding ?b - box) (handempty)
              (unlocked ?c - cell) (have ?k - key) (lying ?k - key) (fits ?k - key ?c - cell))
 (:action pick :parameters (?b - box ?c - cell)
  :precondition (and (at ?b ?c) (handempty))
  :effect (and (holding ?b) (not (at ?b ?c)) (not (occupied ?c)) (not (handempty))))
 (:action put :parameters (?b - box ?c - cell)
  :precondition (and (holding ?b) (not (occupied ?c)) (unlocked ?c))
  :effect (and (at ?b ?c) (occupied ?c) (handempty) (not (holding ?b))))
 (:action take :parameters (?k - key)
  :precondition (and (lying ?k) (handempty))
  :effect (and (have ?k) (not (lying ?k))))
 (:action unlock :parameters (?c - cell ?k - key)
  :precondition (and (have ?k) (fits ?k ?c))
  :effect (unlocked ?c)))
"""

PROBLEM = """
(define (problem swap) (:domain cells)
 (:objects a c d - cell x y - box k1 k2 k3 - key)
 (:init (at x a) (occupied a) (at y c) (occupied c) (handempty) (unlocked a) (unlocked d)
        (lying k1) (lying k2) (lying k3) (fits k1 c) (fits k2 c) (fits k3 d))
 (:goal (at x c)))
"""


@pytest.fixture(scope="module")
def task_and_files():
    domain = parse_domain(DOMAIN)
    problem = parse_problem(PROBLEM, domain=domain)
    return domain, problem, ground_task(domain, problem)


def test_complement_and_disjunctive_landmarks(task_and_files) -> None:
    _domain, _problem, task = task_and_files
    lm = Landmarks(task, disjunctive=True)
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    assert {"(at x c)", "(holding x)", "(not (occupied c))", "(unlocked c)"} <= set(names)
    assert "(have k1) | (have k2)" in names  # k3 fits another cell: not in the disjunction
    # Orderings: the cell is cleared and unlocked before x is put there, a key is had before it opens.
    assert lm.parents[names["(at x c)"]] >> names["(not (occupied c))"] & 1
    assert lm.parents[names["(unlocked c)"]] >> names["(have k1) | (have k2)"] & 1
    # Landmark truth: the complement holds where the atom is false, a disjunction on either fact.
    init = task.init
    assert not lm.holds(names["(not (occupied c))"], init)
    atom = {str(a): i for i, a in enumerate(task.atoms)}
    after = (init & ~(1 << atom["(occupied c)"])) | (1 << atom["(have k2)"])
    assert lm.holds(names["(not (occupied c))"], after)
    assert lm.holds(names["(have k1) | (have k2)"], after)
    # h counts every landmark not true initially: the goal, holding x, the cleared and unlocked
    # cell, a key, and the pick of y the cleared cell needs (holding y is not a landmark: pick y c
    # is the cell's only first achiever, holding y only its effect).
    plain = Landmarks(task)  # disjunctive landmarks are off by default
    assert not any("|" in plain.describe(k) for k in range(len(plain.facts)))
    accepted = lm.accept(0, init)
    h, _preferred = lm.value(accepted, init, task.applicable(init))
    assert h == sum(1 for k in range(len(lm.facts)) if not lm.holds(k, init))
    assert h >= 5


def test_accepted_landmark_false_again_counts_while_still_needed(task_and_files) -> None:
    """Required again (LAMA): an accepted landmark that is false again counts while a landmark
    ordered after it is not accepted."""
    _domain, _problem, task = task_and_files
    lm = Landmarks(task)
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    atom = {str(a): i for i, a in enumerate(task.atoms)}
    clear = names["(not (occupied c))"]
    # Accept "c is clear" on a path, then put y back: c is occupied again before x went there.
    cleared = (task.init & ~(1 << atom["(occupied c)"]) & ~(1 << atom["(at y c)"])) | (
        1 << atom["(holding y)"]
    )
    accepted = lm.accept(lm.accept(0, task.init), cleared)
    assert accepted >> clear & 1
    h_clear, _ = lm.value(accepted, cleared)
    h_back, _ = lm.value(accepted, task.init)
    assert h_back == h_clear + 1


def test_lama_solves_with_them_and_the_plan_validates(task_and_files) -> None:
    domain, problem, _task = task_and_files
    result = plan(domain, problem, planner="lama")
    assert result.status == "solved"
    assert validate_plan(domain, problem, result.plan).valid
    steps = [str(s) for s in result.plan]
    assert steps.index("(pick y c)") < steps.index("(put x c)")
