"""The lazy searches' batched queues and the landmark heuristic's cached tables keep their values.

Both are speed-ups that must not change what the search does: the batched queue must pop operators
in the order of one heap entry per operator keyed (h, insertion counter), and the landmark count,
its preferred operators and the accepted sets must equal their definitions.
"""

from __future__ import annotations

import random
from array import array
from heapq import heappop, heappush
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import OP_IDS, take_next

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


@pytest.mark.parametrize("packed", [False, True])
def test_batched_queue_pops_in_per_operator_fifo_order(packed: bool) -> None:
    # the lazy searches keep an entry's operators as a packed array (OP_IDS): same order as a list
    rng = random.Random(5)
    batched: list = []
    single: list = []
    counter = expansion = 0
    got, expected = [], []
    for _ in range(400):
        if rng.random() < 0.45 or not single:
            # an expansion: its successors share one h
            h = rng.randint(0, 6)
            ops = sorted(rng.sample(range(50), rng.randint(1, 6)))
            sid = rng.randint(0, 999)
            expansion += 1
            heappush(batched, (h, expansion, 0, sid, array(OP_IDS, ops) if packed else ops))
            for op in ops:
                counter += 1
                heappush(single, (h, counter, sid, op))
        else:
            _, _, sid, op = heappop(single)
            expected.append((sid, op))
            got.append(take_next(batched))
    while single:
        _, _, sid, op = heappop(single)
        expected.append((sid, op))
        got.append(take_next(batched))
    assert not batched
    assert got == expected and len(got) > 300


def _walk(task, steps: int, seed: int) -> list[int]:
    rng = random.Random(seed)
    states, state = [], task.init
    for _ in range(steps):
        ops = task.applicable(state)
        if not ops:
            break
        state = task.apply(state, rng.choice(ops))
        states.append(state)
    return states


def _reference_accept(lm: Landmarks, accepted: int, state: int) -> int:
    todo = [k for k in range(len(lm.facts)) if lm.holds(k, state) and not accepted >> k & 1]
    changed = True
    while changed:
        changed = False
        for k in todo:
            if not accepted >> k & 1 and accepted & lm.parents[k] == lm.parents[k]:
                accepted |= 1 << k
                changed = True
    return accepted


def _reference_value(
    lm: Landmarks, accepted: int, state: int, applicable: list[int]
) -> tuple[int, list[int]]:
    h = sum(1 for k in range(len(lm.facts)) if not accepted >> k & 1)
    # Accepted landmarks false again count when still needed: goals, and landmarks greedy-necessarily
    # ordered before one not accepted yet (reasonable orders only delay acceptance, as in LAMA).
    needed = lm.goal_mask
    for k in range(len(lm.facts)):
        if not accepted >> k & 1:
            needed |= lm.gn_parents[k]
    h += sum(
        1 for k in range(len(lm.facts)) if needed >> k & 1 and accepted >> k & 1 and not lm.holds(k, state)
    )
    ready = {
        k for k in range(len(lm.facts)) if not accepted >> k & 1 and accepted & lm.parents[k] == lm.parents[k]
    }
    return h, [i for i in applicable if any(k in ready for k in lm.lm_adds.get(i, ()))]


@pytest.mark.parametrize(
    "folder,problem",
    [
        ("blocks", "probBLOCKS-9-2.pddl"),
        ("gripper", "prob06.pddl"),
        ("miconic-simpleadl", "s4-0.pddl"),
    ],
)
def test_landmark_count_matches_its_definition(folder: str, problem: str) -> None:
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    task = ground_task(domain, load_problem(FIXTURES / folder / problem, domain))
    lm = Landmarks(task)
    assert lm.facts, "the test needs landmarks"
    checked = 0
    for seed in range(6):
        accepted = reference = lm.accept(0, task.init)
        assert accepted == _reference_accept(lm, 0, task.init)
        for state in _walk(task, 40, seed):
            accepted = lm.accept(accepted, state)
            reference = _reference_accept(lm, reference, state)
            assert accepted == reference
            applicable = task.applicable(state)
            assert lm.value(accepted, state, applicable) == _reference_value(lm, accepted, state, applicable)
            checked += 1
    assert checked > 100
