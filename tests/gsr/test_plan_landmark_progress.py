"""Past/future landmark progression (``gsr.plan.landmarks_progress``) and lama-first's switches.

On three blocks with goal on(a,b), on(b,c): on(b,c) ->r on(a,b) is a reasonable order, so on(a,b)
reached first is past but stays future (it must be reached again after on(b,c)); a goal landmark
destroyed again is future; a greedy-necessary predecessor false again before its successor was
first reached is future again. The sum counts the future landmarks.
"""

from __future__ import annotations

import random
import time
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem, parse_domain, parse_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import INF, Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.landmarks_progress import Progression
from gsr.plan.search import FD_LAMA_FIRST, LAMA_FIRST, LamaOptions, lazy_lama
from gsr.validate import validate_plan

from .test_plan_landmark_orders import DOMAIN, TOWER

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def _tower():
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TOWER, domain=domain)
    task = ground_task(domain, problem)
    lm = Landmarks(task)
    return domain, problem, task, lm, Progression(lm)


def _walk(task, prog, steps):
    state, status = task.init, prog.initial(task.init)
    for name, args in steps:
        op = next(i for i, o in enumerate(task.ops) if o.name == name and o.args == args)
        state = task.apply(state, op)
        status = prog.progress(status, state)
    return state, status


def test_initial_status_past_is_what_holds() -> None:
    _d, _p, task, lm, prog = _tower()
    past, fut = prog.initial(task.init)
    for k in range(len(lm.facts)):
        assert bool(past >> k & 1) == lm.holds(k, task.init)
        assert bool(fut >> k & 1) == (not lm.holds(k, task.init))
    assert prog.value((past, fut)) == fut.bit_count() > 0


def test_reasonable_order_violated_keeps_the_landmark_future() -> None:
    _d, _p, task, lm, prog = _tower()
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    ab, bc = names["(on a b)"], names["(on b c)"]
    assert (bc, ab) in lm.orders.reasonable
    state, (past, fut) = _walk(task, prog, [("pick-up", ("a",)), ("stack", ("a", "b"))])
    assert lm.holds(ab, state) and past >> ab & 1  # reached: past ...
    assert fut >> ab & 1  # ... but future again: on(b,c) is not past
    early = prog.value((past, fut))
    state, (past, fut) = _walk(
        task,
        prog,
        [("pick-up", ("b",)), ("stack", ("b", "c")), ("pick-up", ("a",)), ("stack", ("a", "b"))],
    )
    assert task.is_goal(state) and fut == 0 and prog.value((past, fut)) == 0 < early


def test_goal_and_greedy_necessary_landmarks_come_back() -> None:
    _d, _p, task, lm, prog = _tower()
    names = {lm.describe(k): k for k in range(len(lm.facts))}
    bc = names["(on b c)"]
    # on(b,c) reached and undone: a goal landmark false again is future.
    _s, (past, fut) = _walk(task, prog, [("pick-up", ("b",)), ("stack", ("b", "c")), ("unstack", ("b", "c"))])
    assert past >> bc & 1 and fut >> bc & 1
    # holding(b) is greedy-necessary before on(b,c): put down before stacking, it is future again.
    hb = names["(holding b)"]
    assert lm.gn_parents[bc] >> hb & 1
    _s, (past, fut) = _walk(task, prog, [("pick-up", ("b",))])
    assert past >> hb & 1 and not fut >> hb & 1
    _s, (past, fut) = _walk(task, prog, [("pick-up", ("b",)), ("put-down", ("b",))])
    assert past >> hb & 1 and fut >> hb & 1


def test_a_future_landmark_nothing_adds_is_a_dead_end() -> None:
    _d, _p, task, _lm, prog = _tower()
    past, fut = prog.initial(task.init)
    prog.unachievable = fut & -fut  # pretend no operator adds one future landmark
    assert prog.value((past, fut)) == INF


@pytest.mark.parametrize(
    "folder,problem",
    [("blocks", "probBLOCKS-9-2.pddl"), ("gripper", "prob06.pddl"), ("miconic-simpleadl", "s4-0.pddl")],
)
def test_progression_matches_its_definition_on_random_walks(folder: str, problem: str) -> None:
    """Along random walks: past = every landmark that held on the path; future = not past, or
    false now and (a goal, or greedy-necessary before a landmark not past), or the head of a
    reasonable order whose tail is not past."""
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    task = ground_task(domain, load_problem(FIXTURES / folder / problem, domain))
    lm = Landmarks(task)
    prog = Progression(lm)
    m = len(lm.facts)
    reasonable = lm.orders.reasonable if lm.orders else []
    checked = 0
    for seed in range(4):
        rng = random.Random(seed)
        state = task.init
        status = prog.initial(state)
        seen = {k for k in range(m) if lm.holds(k, state)}
        for _ in range(40):
            ops = task.applicable(state)
            if not ops:
                break
            state = task.apply(state, rng.choice(ops))
            status = prog.progress(status, state)
            seen |= {k for k in range(m) if lm.holds(k, state)}
            past, fut = status
            assert {k for k in range(m) if past >> k & 1} == seen
            for k in range(m):
                false_now = not lm.holds(k, state)
                needed = lm.goal_mask >> k & 1 or any(
                    lm.gn_parents[j] >> k & 1 and j not in seen for j in range(m)
                )
                early = any(b == k and a not in seen for a, b in reasonable)
                expected = k not in seen or (false_now and bool(needed)) or early
                assert bool(fut >> k & 1) == expected, (folder, k, lm.describe(k))
            checked += 1
    assert checked > 60


@pytest.mark.parametrize(
    "options",
    [FD_LAMA_FIRST, LAMA_FIRST, LamaOptions(progression="past-future"), LamaOptions(lm_preferred=False)],
)
def test_gsr_and_fd_search_rules_plan_and_validate(options: LamaOptions) -> None:
    domain = load_domain(FIXTURES / "blocks" / "domain.pddl")
    problem = load_problem(FIXTURES / "blocks" / "probBLOCKS-9-2.pddl", domain)
    task = ground_task(domain, problem)
    trace: list = []
    res = lazy_lama(
        task, Relaxation(task, unit=True), Landmarks(task), time.perf_counter() + 30, options, trace
    )
    assert res.status == "solved"
    assert validate_plan(domain, problem, task.to_plan(res.ops)).valid
    ff_values = [v for _e, name, v in trace if name == "ff"]
    assert ff_values == sorted(ff_values, reverse=True) and len(set(ff_values)) == len(ff_values)


def test_unknown_progression_is_an_error() -> None:
    _d, _p, task, lm, _prog = _tower()
    with pytest.raises(ValueError, match="progression"):
        lazy_lama(
            task, Relaxation(task, unit=True), lm, time.perf_counter() + 5, LamaOptions(progression="x")
        )
