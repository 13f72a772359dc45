"""How much a ``gsr solve`` costs with the grounder backend: planner calls, prompts built, CPU per solve.

    python benchmarks/bench_solve.py [--tasks 5] [--repeat 3] [--steps N] [--suite gsr-bench-gen|rlbench|...]

Picks the first tasks of a suite (default: the generated GSR-Bench tasks, gsr-bench-gen, seed 0) that the grounder solves in 6 or more
steps (exactly N with ``--steps N``), counts ``plan_graph`` calls and prompts built during one solve, and times repeated solves (wall and
CPU time, medians: the machine may be shared, so CPU is the figure to compare). Figures: docs/performance.md (Reasoner).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Iterator
from contextlib import contextmanager
from unittest import mock

from gsr.benchmarks.suites import get_suite

import gsr.plan.api as plan_api
import gsr.reason.loop as loop
from gsr.reason.reasoner import solve


@contextmanager
def counting_planner_and_prompts() -> Iterator[dict[str, int]]:
    """Counts ``plan_graph`` calls and steps-mode prompts built while it is open (the dict it yields;
    the real functions still run). Used here and by the tests of the one-plan solve."""
    calls = {"plan": 0, "prompt": 0}
    real_plan, real_prompt = plan_api.plan_graph, loop.build_prompt

    def counting_plan(*a, **k):
        calls["plan"] += 1
        return real_plan(*a, **k)

    def counting_prompt(*a, **k):
        calls["prompt"] += 1
        return real_prompt(*a, **k)

    with (
        mock.patch.object(plan_api, "plan_graph", counting_plan),
        mock.patch.object(loop, "build_prompt", counting_prompt),
    ):
        yield calls


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--suite", default="gsr-bench-gen", help="task suite (seed 0)")
    ap.add_argument("--steps", type=int, default=None, help="only tasks solved in exactly this many steps")
    args = ap.parse_args()

    picked = []
    for task in get_suite(args.suite).tasks(None, 0):
        with counting_planner_and_prompts() as calls:
            result = solve(task.initial, task.instruction)
        wanted = len(result.steps) == args.steps if args.steps else len(result.steps) >= 6
        if result.status == "solved" and wanted:
            picked.append((task, len(result.steps), dict(calls)))
        if len(picked) == args.tasks:
            break
    print(
        "| task | steps | planner calls | prompts built | wall per solve (median) | CPU per solve (median) |"
    )
    print("|---|---:|---:|---:|---:|---:|")
    for task, steps, counted in picked:
        walls, cpus = [], []
        for _ in range(args.repeat):
            wall, cpu = time.perf_counter(), time.process_time()
            solve(task.initial, task.instruction)
            cpus.append(time.process_time() - cpu)
            walls.append(time.perf_counter() - wall)
        print(
            f"| {task.id} | {steps} | {counted['plan']} | {counted['prompt']} | "
            f"{statistics.median(walls) * 1000:.0f} ms | {statistics.median(cpus) * 1000:.0f} ms |"
        )


if __name__ == "__main__":
    main()
