"""Mutex groups and reasonable orders of the landmark graph on small hand-made blocks tasks.

Goal on(a,b) and on(b,c) from three blocks on the table: stacking b on c needs b clear, which
on(a,b) destroys, so on(b,c) is reasonably ordered before on(a,b) (Hoffmann et al.'s example).
The landmark count then does not accept on(a,b) reached first.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem, parse_domain, parse_problem
from gsr.plan import plan
from gsr.plan.grounding import ground_task
from gsr.plan.landmarks import Landmarks
from gsr.plan.landmarks_mutex import MutexGroups
from gsr.validate import validate_plan

DOMAIN = """
(define (domain blocks) (:requirements :strips)
 (:predicates (on ?x ?y) (ontable ?x) (clear ?x) (handempty) (holding ?x))
 (:action pick-up :parameters (?x) :precondition (and (clear ?x) (ontable ?x) (handempty))
  :effect (and (not (ontable ?x)) (not (clear ?x)) (not (handempty)) (holding ?x)))
 (:action put-down :parameters (?x) :precondition (holding ?x)
  :effect (and (not (holding ?x)) (clear ?x) (handempty) (ontable ?x)))
 (:action stack :parameters (?x ?y) :precondition (and (holding ?x) (clear ?y))
  :effect (and (not (holding ?x)) (not (clear ?y)) (clear ?x) (handempty) (on ?x ?y)))
 (:action unstack :parameters (?x ?y) :precondition (and (on ?x ?y) (clear ?x) (handempty))
  :effect (and (holding ?x) (clear ?y) (not (clear ?x)) (not (handempty)) (not (on ?x ?y)))))
"""

TOWER = """
(define (problem tower) (:domain blocks) (:objects a b c)
 (:init (clear a) (clear b) (clear c) (ontable a) (ontable b) (ontable c) (handempty))
 (:goal (and (on a b) (on b c))))
"""

APART = """
(define (problem apart) (:domain blocks) (:objects a b c d)
 (:init (clear a) (clear b) (clear c) (clear d) (ontable a) (ontable b) (ontable c) (ontable d)
        (handempty))
 (:goal (and (on a b) (on c d))))
"""


def _task(problem_text: str):
    domain = parse_domain(DOMAIN)
    problem = parse_problem(problem_text, domain=domain)
    return domain, problem, ground_task(domain, problem)


def _atom(task, text: str) -> int:
    return next(i for i, a in enumerate(task.atoms) if str(a) == text)


def test_mutex_groups_are_blocks_invariants() -> None:
    _d, _p, task = _task(TOWER)
    groups = MutexGroups(task)
    a = lambda text: _atom(task, text)  # noqa: E731
    # per block: clear, something on it, held; per block: on something, on the table, held; one hand
    assert groups.mutex(a("(clear b)"), a("(on a b)"))
    assert groups.mutex(a("(on a b)"), a("(on a c)"))
    assert groups.mutex(a("(ontable a)"), a("(holding a)"))
    assert groups.mutex(a("(handempty)"), a("(holding c)"))
    assert groups.mutex(a("(holding a)"), a("(holding b)"))
    # never mutex: both can hold in one state
    assert not groups.mutex(a("(clear a)"), a("(clear b)"))
    assert not groups.mutex(a("(on a b)"), a("(on b c)"))
    assert not groups.mutex(a("(ontable a)"), a("(handempty)"))


def test_mutex_budget_counts_work_not_seconds() -> None:
    """The budget is work: the same task and budget give the same groups on any machine or load."""
    _d, _p, task = _task(TOWER)
    whole = MutexGroups(task)
    assert whole.complete and whole.work > 0
    cut = [MutexGroups(task, max_work=whole.work // 4) for _ in range(2)]
    assert not cut[0].complete
    assert cut[0].work >= whole.work // 4
    assert cut[0].groups == cut[1].groups and cut[0].work == cut[1].work
    assert set(cut[0].groups) <= set(whole.groups) and len(cut[0].groups) < len(whole.groups)
    assert MutexGroups(task, max_work=0).groups == []


def test_landmarks_reuse_given_mutex_groups() -> None:
    """A second graph of one task built on the first's mutex groups has the same landmarks and orders."""
    _d, _p, task = _task(TOWER)
    first = Landmarks(task)
    assert first.orders is not None
    given = Landmarks(task, disjunctive=True, mutexes=first.orders.mutexes)
    fresh = Landmarks(task, disjunctive=True)
    assert given.orders is not None and given.orders.mutexes is first.orders.mutexes
    assert given.lm_facts == fresh.lm_facts
    assert given.parents == fresh.parents and given.gn_parents == fresh.gn_parents


def test_reasonable_order_on_bc_before_on_ab() -> None:
    _d, _p, task = _task(TOWER)
    lm = Landmarks(task)
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    ab, bc = names["(on a b)"], names["(on b c)"]
    assert (bc, ab) in lm.orders.reasonable
    assert (ab, bc) not in lm.orders.reasonable
    assert lm.parents[ab] >> bc & 1  # acceptance of on(a,b) waits for on(b,c)
    assert not lm.gn_parents[ab] >> bc & 1  # not a greedy-necessary order: no "required again"
    # on(a,b) reached first (pick-up a, stack a b) is not accepted: it still counts.
    state = task.init
    accepted = lm.accept(0, state)
    for name, args in (("pick-up", ("a",)), ("stack", ("a", "b"))):
        op = next(i for i, o in enumerate(task.ops) if o.name == name and o.args == args)
        state = task.apply(state, op)
        accepted = lm.accept(accepted, state)
    assert lm.holds(ab, state)
    assert not accepted >> ab & 1
    h_wrong, _ = lm.value(accepted, state)
    # The same on(a,b) after on(b,c) is accepted.
    state = task.init
    accepted = lm.accept(0, state)
    for name, args in (
        ("pick-up", ("b",)),
        ("stack", ("b", "c")),
        ("pick-up", ("a",)),
        ("stack", ("a", "b")),
    ):
        op = next(i for i, o in enumerate(task.ops) if o.name == name and o.args == args)
        state = task.apply(state, op)
        accepted = lm.accept(accepted, state)
    assert accepted >> ab & 1 and accepted >> bc & 1
    assert lm.value(accepted, state)[0] == 0 < h_wrong


def test_no_reasonable_order_between_independent_goals() -> None:
    _d, _p, task = _task(APART)
    lm = Landmarks(task)
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    ab, cd = names["(on a b)"], names["(on c d)"]
    assert (ab, cd) not in lm.orders.reasonable and (cd, ab) not in lm.orders.reasonable
    assert Landmarks(task, reasonable=False).orders is None


def test_lama_plans_the_tower() -> None:
    domain, problem, _ = _task(TOWER)
    result = plan(domain, problem, planner="lama", timeout=20)
    assert result.solved
    assert validate_plan(domain, problem, result.plan).valid
    assert len(result.plan.steps) == 4  # pick-up b, stack b c, pick-up a, stack a b


def test_landmark_profile_reports_the_orders(tmp_path, capsys) -> None:
    from gsr.benchmarks.landmark_profile import main

    (tmp_path / "domain.pddl").write_text(DOMAIN)
    (tmp_path / "tower.pddl").write_text(TOWER)
    assert main([str(tmp_path / "domain.pddl"), str(tmp_path / "tower.pddl"), "--timeout", "20"]) == 0
    fields = dict(item.split("=") for item in capsys.readouterr().out.split())
    assert fields["status"] == "solved" and fields["plan_length"] == "4"
    assert int(fields["reasonable"]) >= 1 and int(fields["mutex_groups"]) >= 3
    assert main([str(tmp_path / "missing.pddl"), str(tmp_path / "tower.pddl")]) == 2


FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


@pytest.mark.parametrize(
    "folder,problem",
    [("blocks", "probBLOCKS-9-2.pddl"), ("gripper", "prob06.pddl"), ("miconic-simpleadl", "s4-0.pddl")],
)
def test_mutex_groups_hold_on_random_walks(folder: str, problem: str) -> None:
    """No state reached by random walks has two atoms of one group; exactly-one groups have one."""
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    task = ground_task(domain, load_problem(FIXTURES / folder / problem, domain))
    groups = MutexGroups(task)
    assert groups.groups
    masks = [
        (sum(1 << a for a in g), exact) for g, exact in zip(groups.groups, groups.exactly_one, strict=True)
    ]
    checked = 0
    for seed in range(5):
        rng = random.Random(seed)
        state = task.init
        for _ in range(60):
            for mask, exact in masks:
                count = (state & mask).bit_count()
                assert count <= 1 and (count == 1 or not exact)
            checked += 1
            ops = task.applicable(state)
            if not ops:
                break
            state = task.apply(state, rng.choice(ops))
    assert checked > 100
