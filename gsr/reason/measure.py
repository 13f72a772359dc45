"""Measure the reasoner on LIBERO task files: success, steps, rejections, repairs and time per mode/backend.

    python -m gsr.reason.measure data/libero --backend grounder --mode steps [--constrained]

For each BDDL file the scene graph and benchmark goal come from gsr.libero; the reasoner gets the
file's instruction (``--given-goal`` hands it the benchmark goal instead). ``bench_goal`` says whether
the benchmark's own goal holds in the final graph, independently of the goal the reasoner used.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.reason.backends import make_backend
from gsr.reason.cases import PROMPT_OPTIONS, libero_cases, split_cases
from gsr.reason.reasoner import solve
from gsr.resources import load_builtin_domain
from gsr.semantics import goal_holds
from gsr.step import Goal


def run_cases(
    cases: list, backend: Any, mode: str, given_goal: bool = False, echo: bool = False, **options: Any
) -> list[dict]:
    """One row per case: status, success, bench_goal, counts and seconds (``echo``: print each row as JSON)."""
    domain = load_builtin_domain()
    rows = []
    for name, graph, bench_goal, instruction in cases:
        goal = Goal(bench_goal, instruction) if given_goal else None
        start = time.perf_counter()
        result = solve(graph, instruction, backend, mode=mode, domain=domain, goal=goal, **options)
        final = result.final_graph or graph
        row = {
            "task": name,
            "status": result.status,
            "success": result.success,
            "bench_goal": goal_holds(domain, bench_goal, state_from_graph(final, domain)),
            "seconds": time.perf_counter() - start,
            "model_seconds": sum(e.seconds for e in result.transcript),
            **result.to_dict()["counts"],
        }
        if not result.success:
            row["message"] = result.message
        rows.append(row)
        if echo:
            print(json.dumps(row), flush=True)
    return rows


def summary(rows: list[dict]) -> dict[str, Any]:
    """Aggregate figures over the rows."""
    n = len(rows)
    calls = sum(r["model_calls"] for r in rows)
    return {
        "tasks": n,
        "success": sum(r["success"] for r in rows),
        "bench_goal": sum(r["bench_goal"] for r in rows),
        "steps": sum(r["steps"] for r in rows),
        "model_calls": calls,
        "rejections": sum(r["rejections"] for r in rows),
        "repairs": sum(r["repairs"] for r in rows),
        "planner_takeovers": sum(r["planner_takeovers"] for r in rows),
        "median_seconds_per_task": statistics.median(r["seconds"] for r in rows) if rows else 0.0,
        "model_seconds_per_call": sum(r["model_seconds"] for r in rows) / calls if calls else 0.0,
    }


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point: print per-task rows (``--rows``) and the summary as JSON."""
    parser = argparse.ArgumentParser(prog="python -m gsr.reason.measure", description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="folder with LIBERO .bddl files (searched recursively)")
    parser.add_argument("--backend", default="grounder")
    parser.add_argument("--mode", default="steps", choices=("steps", "goal", "hybrid"))
    parser.add_argument("--constrained", action="store_true")
    parser.add_argument("--given-goal", action="store_true", help="give the reasoner the benchmark goal")
    parser.add_argument("--max-steps", type=int, default=40)
    parser.add_argument("--repairs", type=int, default=3)
    parser.add_argument("--limit", type=int, default=None, help="only the first N tasks")
    parser.add_argument("--split", default="all", help="all, even or odd tasks (see gsr.reason.tiny_model)")
    parser.add_argument("--compact", action="store_true", help="no examples, action signatures only")
    parser.add_argument("--rows", action="store_true", help="print one JSON line per task too")
    args = parser.parse_args(argv)
    try:
        cases = split_cases(libero_cases(args.folder), args.split)[: args.limit]
        if not cases:
            raise GSRError(f"{args.folder}: no .bddl files")
        backend = make_backend(args.backend)
        rows = run_cases(
            cases,
            backend,
            args.mode,
            args.given_goal,
            echo=args.rows,
            constrained=args.constrained,
            max_steps=args.max_steps,
            max_repairs=args.repairs,
            **(PROMPT_OPTIONS if args.compact else {}),
        )
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    out = {
        "backend": args.backend,
        "mode": args.mode,
        "constrained": args.constrained,
        "split": args.split,
        **summary(rows),
    }
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
