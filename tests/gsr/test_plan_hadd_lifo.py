"""h_add with last-in-first-out buckets (Fast Downward's bucket order, ``Relaxation.lifo``).

The order in which equal-cost facts are settled changes only which best supporter is kept among
equally cheap ones: every fact's cost must be the same as with FIFO buckets, and a search guided
by the resulting h_FF must still find valid plans.
"""

from __future__ import annotations

import random
import time
from pathlib import Path

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import lazy_lama
from gsr.validate import validate_plan

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


@pytest.mark.parametrize(
    "folder,problem",
    [("blocks", "probBLOCKS-9-2.pddl"), ("gripper", "prob06.pddl"), ("miconic-simpleadl", "s4-0.pddl")],
)
def test_lifo_buckets_keep_every_cost_and_plan(monkeypatch, folder: str, problem: str) -> None:
    monkeypatch.setenv("GSR_PLAN_CC", "0")  # the compiled kernels are FIFO only
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    domain = load_domain(FIXTURES / folder / "domain.pddl")
    prob = load_problem(FIXTURES / folder / problem, domain)
    task = ground_task(domain, prob)
    fifo, lifo = Relaxation(task, unit=True), Relaxation(task, unit=True)
    lifo.lifo = True
    rng = random.Random(1)
    state, compared = task.init, 0
    for _ in range(80):
        cost_f, sup_f = fifo.hadd(state)
        cost_l, sup_l = lifo.hadd(state)
        assert cost_f == cost_l
        assert [s >= 0 for s in sup_f] == [s >= 0 for s in sup_l]  # supported facts alike
        compared += 1
        ops = task.applicable(state)
        if not ops:
            break
        state = task.apply(state, rng.choice(ops))
    assert compared > 20
    res = lazy_lama(task, lifo, Landmarks(task), time.perf_counter() + 30)
    assert res.status == "solved"
    assert validate_plan(domain, prob, task.to_plan(res.ops)).valid


@pytest.mark.parametrize(
    "folder,problem", [("blocks", "probBLOCKS-9-2.pddl"), ("miconic-simpleadl", "s4-0.pddl")]
)
def test_c_kernels_pop_lifo_as_python_does(monkeypatch, folder: str, problem: str) -> None:
    """Same costs, best supporters, h_FF and preferred operators from the C kernels and Python."""
    from gsr.plan import relax_c

    domain = load_domain(FIXTURES / folder / "domain.pddl")
    task = ground_task(domain, load_problem(FIXTURES / folder / problem, domain))
    compiled = Relaxation(task, unit=True)
    if not isinstance(compiled.compiled, relax_c.CRelaxation):
        pytest.skip(f"no C kernels here: {relax_c.why_not}")
    compiled.lifo = True
    monkeypatch.setenv("GSR_PLAN_CC", "0")
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    python = Relaxation(task, unit=True)
    python.lifo = True
    assert python.compiled is None
    rng = random.Random(2)
    state = task.init
    for _ in range(60):
        compiled.compiled.hadd(state)
        cost_p, sup_p = python.hadd(state)
        n = len(cost_p)
        cost_c = [float("inf") if c >= 1 << 60 else c for c in compiled.compiled.cost[:n]]
        assert cost_c == cost_p
        assert list(compiled.compiled.sup[:n]) == sup_p
        assert compiled.ff(state) == python.ff(state)
        ops = task.applicable(state)
        if not ops:
            break
        state = task.apply(state, rng.choice(ops))
    compiled.lifo = False
    fifo = Relaxation(task, unit=True)
    assert compiled.ff(state) == fifo.ff(state)
