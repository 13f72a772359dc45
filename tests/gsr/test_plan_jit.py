"""The compiled h_add / h_FF (gsr.plan.relax_jit: C kernels or numba) equals the pure-Python relaxation."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan, relax_jit
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import INF, Relaxation
from gsr.resources import load_builtin_domain
from gsr.validate import validate_plan

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


@pytest.fixture(params=["c", "numba"])
def backend(request, monkeypatch: pytest.MonkeyPatch) -> str:
    """Each test runs with the C kernels and with numba (GSR_PLAN_CC=0), skipping a missing one."""
    from gsr.plan import relax_c

    monkeypatch.setattr(relax_c, "_lib", None)  # chosen again under this test's environment
    if request.param == "c":
        monkeypatch.delenv("GSR_PLAN_CC", raising=False)
        if relax_c.library() is None:
            pytest.skip(f"C kernels unavailable: {relax_c.why_not}")
    else:
        pytest.importorskip("numba", reason="numba not installed (optional extra 'fast')")
        monkeypatch.setenv("GSR_PLAN_CC", "0")
    return request.param


def _kind(relaxation: Relaxation) -> str:
    from gsr.plan.relax_c import CRelaxation

    return "c" if isinstance(relaxation._jit, CRelaxation) else "numba"


def _walk(task, steps: int, seed: int) -> list[int]:
    rng = random.Random(seed)
    states, state = [], task.init
    for _ in range(steps):
        states.append(state)
        ops = list(task.applicable(state))
        if not ops:
            break
        state = task.apply(state, rng.choice(ops))
    return states


def _tasks():
    yield ground_task(
        load_domain(FIXTURES / "blocks" / "domain.pddl"),
        load_problem(FIXTURES / "blocks" / "probBLOCKS-9-2.pddl"),
    )
    # ADL: negative preconditions (complement facts), conditional effects
    yield ground_task(
        load_domain(FIXTURES / "miconic-simpleadl" / "domain.pddl"),
        load_problem(FIXTURES / "miconic-simpleadl" / "s4-0.pddl"),
    )
    name, graph, goal, _ = long_tabletop_task(3)
    domain = load_builtin_domain("tabletop")
    yield ground_task(domain, problem_from_graph(graph, goal, name=name, domain=domain))


@pytest.mark.parametrize("unit", [True, False])
def test_compiled_hadd_and_ff_equal_the_python_path(
    monkeypatch: pytest.MonkeyPatch, unit: bool, backend: str
) -> None:
    for task in _tasks():
        monkeypatch.setenv("GSR_PLAN_JIT", "0")
        python = Relaxation(task, unit=unit)
        monkeypatch.setenv("GSR_PLAN_JIT", "1")
        compiled = Relaxation(task, unit=unit)
        assert python._jit is None and compiled._jit is not None and _kind(compiled) == backend
        states = _walk(task, 40, seed=1)
        assert len(states) > 10
        for state in states:
            cost, sup = python._hadd_buckets(state)
            jit = compiled._jit
            jit.hadd(state)
            got = [INF if c >= relax_jit.UNREACHED else c for c in jit.cost.tolist()]
            # Both stop once the goal is settled; every fact's cost and best supporter agree.
            assert got == cost
            assert jit.sup.tolist() == sup
            h_py, pref_py = python.ff(state)
            h_jit, pref_jit = compiled.ff(state)
            assert h_py == h_jit
            assert pref_py == pref_jit == sorted(pref_py)  # every backend: ascending, the same list
            assert compiled.ff(state, task.applicable(state)) == (h_py, pref_py)
            # the successor generator the search uses with this relaxation
            assert compiled.applicable(state) == task.applicable(state)
        assert compiled.hadd(task.init) == python.hadd(task.init)


def test_large_costs_pop_in_the_same_order(monkeypatch: pytest.MonkeyPatch, backend: str) -> None:
    """Costs past the C kernel's bucket table go to its heap, smaller ones stay in buckets (the
    table's limit, 2^20, lowered to 6 here): costs and supporters still equal the Python path's."""
    from dataclasses import replace

    from gsr.plan import relax_c
    from gsr.plan.task import Task

    monkeypatch.setattr(relax_c, "MAX_BUCKETS", 6)
    base = next(_tasks())
    ops = [replace(o, cost=(4 + i % 7 if i % 3 == 0 else 1 + i % 2)) for i, o in enumerate(base.ops)]
    task = Task(base.atoms, ops, base.init, base.goals)
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    python = Relaxation(task)
    monkeypatch.setenv("GSR_PLAN_JIT", "1")
    compiled = Relaxation(task)
    assert compiled._jit is not None and _kind(compiled) == backend
    for state in _walk(task, 25, seed=4):
        cost, sup = python._hadd_buckets(state)
        compiled._jit.hadd(state)
        assert [INF if c >= relax_jit.UNREACHED else c for c in compiled._jit.cost.tolist()] == cost
        assert compiled._jit.sup.tolist() == sup
        assert compiled.ff(state)[0] == python.ff(state)[0]


@pytest.mark.parametrize("planner", ["lazy-ff", "lama"])
def test_compiled_path_plans_the_same(monkeypatch: pytest.MonkeyPatch, backend: str, planner: str) -> None:
    domain = load_domain(FIXTURES / "gripper" / "domain.pddl")
    problem = load_problem(FIXTURES / "gripper" / "prob06.pddl")
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    expected = plan(domain, problem, planner=planner, timeout=60)
    monkeypatch.setenv("GSR_PLAN_JIT", "1")
    got = plan(domain, problem, planner=planner, timeout=60)
    assert got.status == expected.status == "solved"
    assert got.plan == expected.plan and got.expanded == expected.expanded
    assert validate_plan(domain, problem, got.plan).valid


def test_unreachable_goal_is_infinite(monkeypatch: pytest.MonkeyPatch, backend: str) -> None:
    monkeypatch.setenv("GSR_PLAN_JIT", "1")
    task = next(_tasks())
    relax = Relaxation(task, unit=True)
    # a state with no atoms at all: nothing is applicable, the goal is unreachable
    assert relax.ff(0) == (INF, [])
    assert relax.hadd(0)[0][relax.goal_fact] == INF


def test_python_relaxation_switches_to_the_compiled_path_after_jit_after_seconds(
    monkeypatch: pytest.MonkeyPatch, backend: str
) -> None:
    monkeypatch.delenv("GSR_PLAN_JIT", raising=False)
    monkeypatch.setattr(relax_jit, "JIT_AFTER", 0.0)
    monkeypatch.setattr(relax_jit, "C_AFTER", 0.0)
    monkeypatch.setattr(relax_jit, "C_MIN_EDGES", 10**9)
    task = next(_tasks())  # blocks: below MIN_EDGES, so it starts in Python
    relax = Relaxation(task, unit=True)
    assert relax._jit is None
    states = _walk(task, 5, seed=2)
    first = relax.ff(states[0])  # Python, and its time passes JIT_AFTER
    assert relax._jit is None
    assert relax.ff(states[1]) is not None and relax._jit is not None and _kind(relax) == backend
    again = relax.ff(states[0])
    assert again[0] == first[0] and sorted(again[1]) == sorted(first[1])
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    assert Relaxation(task, unit=True)._jit_open is False


def test_compiled_landmark_exploration_gives_the_same_landmarks_and_values(
    monkeypatch: pytest.MonkeyPatch, backend: str
) -> None:
    from gsr.plan.landmarks import Landmarks

    for task in list(_tasks())[:2]:
        monkeypatch.setenv("GSR_PLAN_JIT", "0")
        python = Landmarks(task)
        assert python._compiled is None
        monkeypatch.setenv("GSR_PLAN_JIT", "1")
        monkeypatch.setattr(relax_jit, "JIT_AFTER", 0.0)  # compiled from the second landmark on
        monkeypatch.setattr(relax_jit, "C_AFTER", 0.0)
        compiled = Landmarks(task)
        assert compiled._compiled is not None
        assert (compiled.facts, compiled.parents, compiled.goal_mask) == (
            python.facts,
            python.parents,
            python.goal_mask,
        )
        acc_p = acc_c = python.accept(0, task.init)
        for state in _walk(task, 30, seed=3):
            acc_p, acc_c = python.accept(acc_p, state), compiled.accept(acc_c, state)
            assert acc_p == acc_c
            h_p, pref_p = python.value(acc_p, state)
            h_c, pref_c = compiled.value(acc_c, state, task.applicable(state))
            assert h_p == h_c and sorted(pref_p) == sorted(pref_c)


def test_without_a_compiler_the_c_kernels_are_skipped_with_a_reason(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from gsr.plan import relax_c

    monkeypatch.setattr(relax_c, "_lib", None)
    monkeypatch.setattr(relax_c, "_cache_dirs", lambda: [tmp_path / "cache"])
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    monkeypatch.delenv("GSR_PLAN_CC", raising=False)
    monkeypatch.delenv("GSR_PLAN_JIT", raising=False)
    assert relax_c.library() is None
    assert "no-such-cc" in relax_c.why_not
    assert not list((tmp_path / "cache").glob("*.so"))  # no half-written library left behind
    task = next(_tasks())
    relax = Relaxation(task, unit=True)  # falls back to numba or Python, same values
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    python = Relaxation(task, unit=True)
    for state in _walk(task, 10, seed=6):
        assert relax.ff(state) == python.ff(state)


def test_c_kernels_build_once_into_the_first_writable_cache(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from gsr.plan import relax_c

    if relax_c.c_compiler() is None:
        pytest.skip("no C compiler")
    monkeypatch.delenv("GSR_PLAN_CC", raising=False)
    monkeypatch.delenv("GSR_PLAN_JIT", raising=False)
    blocked = tmp_path / "blocked"
    blocked.write_text("a file, so no folder can be made under it (even as root)")
    monkeypatch.setattr(relax_c, "_cache_dirs", lambda: [blocked / "sub", tmp_path / "cache"])
    monkeypatch.setattr(relax_c, "_lib", None)
    assert relax_c.library() is not None, relax_c.why_not
    built = list((tmp_path / "cache").glob("relax_kernels-*.so"))
    assert len(built) == 1 and not list((tmp_path / "cache").glob("*.tmp.so"))
    stamp = built[0].stat().st_mtime_ns
    monkeypatch.setattr(relax_c, "_lib", None)
    assert relax_c.library() is not None  # loaded, not rebuilt
    assert built[0].stat().st_mtime_ns == stamp


def test_without_a_system_compiler_zig_from_pypi_builds_the_kernels(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """`pip install 'gsr[compiler]'` is enough: with no CC and no cc/gcc on PATH, Zig's cc builds them."""
    from gsr.plan import relax_c

    pytest.importorskip("ziglang", reason="ziglang not installed (optional extra 'compiler')")
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv("GSR_PLAN_CC", raising=False)
    monkeypatch.delenv("GSR_PLAN_JIT", raising=False)
    monkeypatch.setattr(relax_c.shutil, "which", lambda *_a, **_k: None)
    assert relax_c.c_compiler()[-3:] == ["-m", "ziglang", "cc"]
    monkeypatch.setattr(relax_c, "_cache_dirs", lambda: [tmp_path / "cache"])
    monkeypatch.setattr(relax_c, "_lib", None)
    assert relax_c.library() is not None, relax_c.why_not
    assert len(list((tmp_path / "cache").glob("relax_kernels-*.so"))) == 1
    task = next(_tasks())
    monkeypatch.setenv("GSR_PLAN_JIT", "1")
    compiled = Relaxation(task, unit=True)
    assert _kind(compiled) == "c"
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    python = Relaxation(task, unit=True)
    for state in _walk(task, 10, seed=7):
        assert compiled.ff(state) == python.ff(state)
