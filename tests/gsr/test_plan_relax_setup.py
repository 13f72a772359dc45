"""The relaxation's set-up (issue 18, seventh pass): conditional effects shared by operators hang off
one auxiliary fact whose achievers are those operators, ascending and once each, however the
grounding shares or repeats cond tuples; the C successor generator that shares the relaxation's
operator arrays gives Task.applicable's lists."""

from __future__ import annotations

import random

import pytest

from gsr.pddl.model import Atom
from gsr.plan import relax_jit
from gsr.plan.heuristics import Relaxation
from gsr.plan.relax_c import CRelaxation, CSuccessors
from gsr.plan.task import GroundOp, Task

# Two conditional effects over atoms 0-5 (condition, -, adds, deletes).
E1 = ((1,), (), (2,), ())
E2 = ((3,), (), (4,), (5,))


def _task() -> Task:
    shared = (E1,)  # one tuple object handed to several operators, as grounding does
    both = (E1, E2)
    twice = (E2, E2)  # the same effect twice in one operator
    ops = [
        GroundOp("a", ("x",), 1.0, (0,), (), (1,), (), shared),
        GroundOp("b", ("x",), 1.0, (0,), (), (3,), (), both),
        GroundOp("c", ("x",), 1.0, (1,), (), (), (0,), ()),
        GroundOp("d", ("x",), 1.0, (0,), (), (5,), (), shared),
        GroundOp("e", ("x",), 1.0, (3,), (), (0,), (), twice),
        GroundOp("f", ("x",), 1.0, (0,), (), (2,), (), (E1,)),  # equal to ``shared``, another object
    ]
    atoms = [Atom("p", (str(i),)) for i in range(6)]
    return Task(atoms, ops, 1, [((4,), (5,))])  # "not 5" in the goal: atom 5 gets a complement fact


def test_shared_effects_hang_off_one_fact_with_ordered_achievers() -> None:
    task = _task()
    relax = Relaxation(task, unit=True)
    first_aux = len(task.atoms) + 2 + len(relax.comp)  # after the atoms, G, T and the complements
    unary = range(len(relax.pre))
    # The auxiliary facts each operator adds, and the effect each auxiliary fact triggers.
    aux_of_op = {relax.owner[u]: [f for f in relax.add[u] if f >= first_aux] for u in unary}
    triggered = {
        relax.pre[u][0]: (relax.pre[u][1:], relax.add[u])
        for u in unary
        if relax.owner[u] == -1 and relax.pre[u][0] >= first_aux
    }
    users: dict[int, list[int]] = {}
    for op in sorted(aux_of_op):
        if op < 0:
            continue
        assert len(aux_of_op[op]) == len(set(aux_of_op[op])), "an operator adds an auxiliary fact twice"
        for f in aux_of_op[op]:
            users.setdefault(f, []).append(op)
    by_effect = {effect: ops for f, ops in users.items() for effect in [triggered[f]]}
    comp5 = relax.comp[5]
    # E1 (condition 1, adds 2) is used by a, b, d and f; E2 (condition 3, adds 4 and "not 5") by b and e.
    assert by_effect[((1,), (2,))] == [0, 1, 3, 5]
    assert by_effect[((3,), (4, comp5))] == [1, 4]
    # Numbered in order of first use: E1's fact (first used by a) before E2's (first used by b).
    f1 = next(f for f, eff in triggered.items() if eff == ((1,), (2,)))
    f2 = next(f for f, eff in triggered.items() if eff == ((3,), (4, comp5)))
    assert f1 < f2


def test_shared_operator_arrays_give_the_same_successors() -> None:
    lib = relax_jit.c_library()
    if lib is None:
        pytest.skip("the C kernels are not available (no compiler)")
    task = _task()
    relax = Relaxation(task, unit=True)
    compiled = CRelaxation(relax, lib)
    shared, own = CSuccessors(task, lib, compiled), CSuccessors(task, lib)
    assert shared.pre_idx is compiled.arrays["opre_idx"]
    rng = random.Random(0)
    for _ in range(200):
        state = rng.getrandbits(6)
        assert shared.applicable(state) == own.applicable(state) == task.applicable(state)


def test_ground_operators_hash_and_compare_by_their_fields() -> None:
    a = GroundOp("pick", ("x", "t"), 1.0, (0, 2), (1,), (3,), (0,), ((((1,), (), (2,), ())),))
    b = GroundOp("pick", ("x", "t"), 1.0, (0, 2), (1,), (3,), (0,), ((((1,), (), (2,), ())),))
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a != GroundOp("pick", ("x", "t"), 1.0, (0, 2), (1,), (3,), (0,))
    assert str(a) == "(pick x t)"
