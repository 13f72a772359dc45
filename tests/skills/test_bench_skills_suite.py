"""bench_skills --suite: per-cell report (success, median / p95 wall and CPU time), the episode bound."""

from __future__ import annotations

import time

from gsr.benchmarks.bench_skills import cpu_bounded, failure_kind, p95, suite_markdown

from gsr.diagnosis import Diagnosis
from gsr.step import Step


def test_p95_is_the_nearest_rank() -> None:
    assert p95([3.0]) == 3.0
    assert p95([float(v) for v in range(1, 101)]) == 95.0
    assert p95([5.0, 1.0, 2.0, 4.0, 3.0]) == 5.0


def _row(cat: str, ok: bool, wall: float, reason: str = "goal reached", recoveries: int = 0) -> dict:
    return {
        "id": f"{cat}-{wall}",
        "category": cat,
        "level": "General",
        "success": ok,
        "steps": 3,
        "recoveries": recoveries,
        "reason": reason,
        "wall_s": wall,
        "cpu_s": wall / 2,
    }


def test_suite_markdown_reports_each_cell_and_all() -> None:
    blocked = "step 2 rejected: physical execution failed: step 2 (pick a t): skill pick failed (blocked): x"
    rows = [
        _row("A", True, 10.0, recoveries=1),
        _row("A", False, 30.0, blocked),
        _row("B", True, 20.0),
    ]
    text = suite_markdown(rows)
    lines = text.splitlines()
    a = next(ln for ln in lines if ln.startswith("| A |"))
    assert "1/2 (50%)" in a and "20.0 / 30.0" in a and "blocked 1" in a and "| 1 |" in a
    everything = next(ln for ln in lines if ln.startswith("| all |"))
    assert "2/3 (67%)" in everything and "20.0 / 30.0" in everything


def test_failure_kinds() -> None:
    assert failure_kind("x: skill place_in failed (not_achieved): y") == "not_achieved"
    assert failure_kind("step 4 rejected: episode time bound: 601 of 600 CPU-s spent") == "out_of_time"
    assert failure_kind("step 2: reality diverges from the expected graph: - a on b") == "diverged"


class _Executor:
    def __init__(self) -> None:
        self.calls = 0

    def execute(self, step: Step) -> Diagnosis:
        self.calls += 1
        t = time.process_time()
        while time.process_time() - t < 0.02:  # burn a little CPU, like a skill
            pass
        return Diagnosis(ok=True, step=step)


def test_the_episode_bound_refuses_steps_once_spent() -> None:
    ex = cpu_bounded(_Executor(), cpu_budget=0.01)
    step = Step("pick", ("a", "table"))
    assert ex.execute(step).ok  # the first step runs
    refused = ex.execute(step)
    assert not refused.ok and "episode time bound" in refused.message
    assert ex.calls == 1 and ex.out_of_time
