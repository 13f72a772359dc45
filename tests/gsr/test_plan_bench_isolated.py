"""bench_planner --isolate: what each system's clock covers, and both systems' plans validated."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from gsr.benchmarks.bench_planner import run_isolated

from gsr.plan.fast_downward import find_fast_downward

BLOCKS = Path(__file__).resolve().parents[1] / "fixtures" / "pddl" / "blocks"


def test_planning_from_pddl_files_imports_no_scene_graph_or_validator() -> None:
    # an isolated GSR run pays for the imports planning needs, not for the scene-graph layer
    code = (
        "import sys; from gsr.pddl.parser import load_domain; from gsr.plan import plan; "
        "print(sorted(m for m in ('gsr.scene_graph', 'gsr.validate', 'pydantic') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_isolated_gsr_row_times_planning_and_validates_apart() -> None:
    row = run_isolated("gsr", BLOCKS / "domain.pddl", BLOCKS / "probBLOCKS-10-0.pddl", 60.0, "lama")
    assert row["status"] == "solved" and row["length"] > 0
    assert row["validate_s"] > 0  # checked after the clock stopped
    # the clock runs from spawning the interpreter to the plan: it covers the in-process planning time
    assert row["time"] >= row["plan_time"] > 0
    assert row["cpu"] == row["cpu_total"] > 0  # the child's own CPU since its start


def test_isolated_fd_row_is_validated_too() -> None:
    if find_fast_downward() is None:
        pytest.skip("Fast Downward is not installed (pip install up-fast-downward)")
    row = run_isolated("fd", BLOCKS / "domain.pddl", BLOCKS / "probBLOCKS-10-0.pddl", 60.0, "lama")
    assert row["status"] == "solved" and row["length"] > 0 and row["validate_s"] > 0
    assert row["cpu"] > 0 and 0 < row["time"] <= 60.0


def test_cpu_clock_limits_cpu_seconds_and_reports_wall_too() -> None:
    # --clock cpu: the limit is on the child's CPU seconds; a solved row reports both clocks
    row = run_isolated("gsr", BLOCKS / "domain.pddl", BLOCKS / "probBLOCKS-10-0.pddl", 60.0, "lama", "cpu")
    assert row["status"] == "solved" and row["length"] > 0 and row["validate_s"] > 0
    assert 0 < row["cpu"] == row["cpu_total"] < 60.0 and row["time"] > 0


def test_cpu_clock_timeout_counts_the_limit_in_cpu_and_measured_wall() -> None:
    # a 1 s CPU limit stops GSR (its imports and grounding alone are near that) through SIGXCPU, not the wall
    row = run_isolated(
        "gsr", BLOCKS / "domain.pddl", BLOCKS / "probBLOCKS-17-0.pddl", 1.0, "astar-blind", "cpu"
    )
    assert row["status"] == "timeout" and row["length"] is None
    assert row["cpu"] == 1.0 and not row.get("killed") and row["time"] > 0.5


def test_cpu_clock_fd_row() -> None:
    if find_fast_downward() is None:
        pytest.skip("Fast Downward is not installed (pip install up-fast-downward)")
    row = run_isolated("fd", BLOCKS / "domain.pddl", BLOCKS / "probBLOCKS-10-0.pddl", 60.0, "lama", "cpu")
    assert row["status"] == "solved" and row["length"] > 0 and 0 < row["cpu"] < 60.0


def test_failures_lists_problems_some_system_did_not_solve() -> None:
    from gsr.benchmarks.bench_planner import failures

    res = {
        "set": "s",
        "rows": [
            {"problem": "p1", "gsr": {"status": "solved"}, "fd": {"status": "solved"}},
            {"problem": "p2", "gsr": {"status": "timeout"}, "fd": {"status": "solved"}},
            {"problem": "p3", "gsr": {"status": "solved"}, "pyperplan": {"status": "n/a"}},
        ],
    }
    assert failures([res]) == ["s: p2 (gsr timeout, fd solved)"]


def test_skip_pick_leaves_out_exactly_the_picked_problems() -> None:
    from gsr.benchmarks.bench_planner import problems

    fractions = [0.1, 0.25, 0.5, 0.9]
    every, picked = problems("blocks"), problems("blocks", pick=fractions)
    rest = problems("blocks", skip=fractions)
    assert picked and rest and set(rest) | set(picked) == set(every) and not set(rest) & set(picked)
    assert rest == [p for p in every if p not in picked]  # same order
