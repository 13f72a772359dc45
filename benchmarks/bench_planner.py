"""Planner benchmark: GSR's planner vs pyperplan (GBFS + h_FF) vs Fast Downward lama-first on the IPC sets.

Usage: python benchmarks/bench_planner.py [--sets blocks,gripper,miconic-simpleadl] [--timeout 60]
       [--planner lazy-ff] [--systems gsr,pyperplan,fd] [--json] [--tabletop]

GSR runs in-process (parsing + grounding + search timed); pyperplan and Fast Downward run as
subprocesses (their interpreter start-up and FD's translator included), PYTHONHASHSEED=0.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from gsr.errors import GSRError  # noqa: E402
from gsr.pddl.parser import load_domain, load_problem  # noqa: E402
from gsr.plan import plan  # noqa: E402
from gsr.plan.fast_downward import run_fast_downward  # noqa: E402

DATA = REPO.parent / "shared" / "data"
SETS = ("blocks", "gripper", "miconic-simpleadl")
ADL_SETS = frozenset({"miconic-simpleadl"})  # pyperplan handles STRIPS only


def problems(domain_set: str) -> list[Path]:
    """Problem files of one IPC set, in a natural order (by size, then name)."""
    folder = DATA / "pddl" / domain_set
    files = [p for p in folder.glob("*.pddl") if p.name != "domain.pddl"]
    return sorted(files, key=lambda p: (len(p.stem), p.stem))


def run_gsr(domain_file: Path, problem_file: Path, timeout: float, planner: str) -> dict:
    """Parse, ground and search in-process; wall time of all three."""
    start = time.perf_counter()
    try:
        domain = load_domain(domain_file)
        problem = load_problem(problem_file, domain)
        result = plan(domain, problem, planner=planner, timeout=timeout)
    except GSRError as err:
        return {"status": "error", "time": time.perf_counter() - start, "length": None, "message": str(err)}
    elapsed = time.perf_counter() - start
    length = len(result.plan) if result.plan is not None else None
    return {"status": result.status, "time": elapsed, "length": length, "expanded": result.expanded}


def run_pyperplan(domain_file: Path, problem_file: Path, timeout: float) -> dict:
    """pyperplan -s gbf -H hff as a subprocess, on copies (it writes PROBLEM.soln beside the problem)."""
    with tempfile.TemporaryDirectory(prefix="gsr-pyperplan-") as tmp:
        dom = Path(tmp) / "domain.pddl"
        prob = Path(tmp) / problem_file.name
        shutil.copy(domain_file, dom)
        shutil.copy(problem_file, prob)
        cmd = [sys.executable, "-m", "pyperplan", "-s", "gbf", "-H", "hff", str(dom), str(prob)]
        env = dict(os.environ, PYTHONHASHSEED="0")
        start = time.perf_counter()
        try:
            subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, cwd=tmp)
        except subprocess.TimeoutExpired:
            return {"status": "timeout", "time": timeout, "length": None}
        elapsed = time.perf_counter() - start
        soln = prob.with_suffix(".pddl.soln")
        if not soln.is_file():
            return {"status": "unsolved", "time": elapsed, "length": None}
        steps = [ln for ln in soln.read_text().splitlines() if ln.strip().startswith("(")]
        return {"status": "solved", "time": elapsed, "length": len(steps)}


def run_fd(domain_file: Path, problem_file: Path, timeout: float) -> dict:
    """Fast Downward --alias lama-first (driver, translator and search) as a subprocess."""
    start = time.perf_counter()
    try:
        status, found, _ = run_fast_downward(domain_file, problem_file, timeout)
    except GSRError as err:
        return {"status": "n/a", "time": 0.0, "length": None, "message": str(err)}
    elapsed = time.perf_counter() - start
    return {"status": status, "time": elapsed, "length": len(found) if found is not None else None}


def bench_set(domain_set: str, systems: list[str], timeout: float, planner: str, verbose: bool) -> dict:
    """Run every system on every problem of one set; per-problem rows and per-system summaries."""
    domain_file = DATA / "pddl" / domain_set / "domain.pddl"
    rows = []
    for prob in problems(domain_set):
        row: dict = {"problem": prob.name}
        for system in systems:
            if system == "gsr":
                row[system] = run_gsr(domain_file, prob, timeout, planner)
            elif system == "pyperplan":
                if domain_set in ADL_SETS:
                    row[system] = {"status": "n/a", "time": 0.0, "length": None}
                else:
                    row[system] = run_pyperplan(domain_file, prob, timeout)
            elif system == "fd":
                row[system] = run_fd(domain_file, prob, timeout)
        if verbose:
            cells = "  ".join(
                f"{s}:{row[s]['status']}/{row[s]['time']:.2f}s/{row[s]['length']}" for s in systems
            )
            print(f"{domain_set}/{prob.name}: {cells}", file=sys.stderr, flush=True)
        rows.append(row)
    summary = {}
    for system in systems:
        results = [r[system] for r in rows]
        if all(r["status"] == "n/a" for r in results):
            summary[system] = {"coverage": "n/a"}
            continue
        solved = [r for r in results if r["status"] == "solved"]
        summary[system] = {
            "coverage": len(solved),
            "tasks": len(results),
            "total_time": sum(r["time"] for r in results),
            "total_length": sum(r["length"] for r in solved),
        }
    return {"set": domain_set, "rows": rows, "summary": summary}


def bench_tabletop(timeout: float, planner: str) -> dict:
    """Plan the LIBERO .bddl tasks through gsr.libero.libero_task; median times (all, >= 10 steps)."""
    try:
        from gsr.plan.cli import load_libero
    except ImportError as err:  # pragma: no cover - depends on the tree
        return {"status": f"n/a ({err})"}
    times, long_times, rows = [], [], []
    for bddl in sorted((DATA / "libero").rglob("*.bddl")):
        try:
            domain, problem = load_libero(bddl, None)
        except GSRError as err:
            return {"status": f"n/a ({err})"}
        result = plan(domain, problem, planner=planner, timeout=timeout)
        rows.append(
            {
                "task": bddl.name,
                "status": result.status,
                "time": result.time,
                "length": len(result.plan) if result.plan else None,
            }
        )
        if result.solved:
            times.append(result.time)
            if len(result.plan) >= 10:
                long_times.append(result.time)
    return {
        "tasks": len(rows),
        "solved": len(times),
        "median_time": statistics.median(times) if times else None,
        "long_tasks": len(long_times),
        "median_time_long": statistics.median(long_times) if long_times else None,
        "rows": rows,
    }


def print_table(results: list[dict], systems: list[str]) -> None:
    """A plain-text table: coverage, total time, total plan length, time ratio vs Fast Downward."""
    print(f"{'set':<20}{'system':<11}{'coverage':>10}{'time (s)':>11}{'length':>9}{'time/FD':>9}")
    for res in results:
        fd = res["summary"].get("fd", {})
        for system in systems:
            s = res["summary"][system]
            if s["coverage"] == "n/a":
                print(f"{res['set']:<20}{system:<11}{'n/a':>10}")
                continue
            ratio = ""
            if fd.get("coverage") not in (None, "n/a") and fd["total_time"] > 0:
                ratio = f"{s['total_time'] / fd['total_time']:.2f}"
            cov = f"{s['coverage']}/{s['tasks']}"
            print(
                f"{res['set']:<20}{system:<11}{cov:>10}{s['total_time']:>11.2f}{s['total_length']:>9}{ratio:>9}"
            )


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", default=",".join(SETS))
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--planner", default="lazy-ff")
    parser.add_argument("--systems", default="gsr,pyperplan,fd")
    parser.add_argument("--json", action="store_true", help="print the full results as JSON")
    parser.add_argument("--tabletop", action="store_true", help="also plan the LIBERO tasks")
    parser.add_argument("-v", "--verbose", action="store_true", help="one line per task on stderr")
    args = parser.parse_args(argv)
    systems = [s for s in args.systems.split(",") if s]
    sets = [s for s in args.sets.split(",") if s]
    unknown = [s for s in sets if s not in SETS]
    if unknown:
        parser.error(f"unknown set(s) {unknown}; choose from {', '.join(SETS)}")
    results = [bench_set(s, systems, args.timeout, args.planner, args.verbose) for s in sets]
    out: dict = {"timeout": args.timeout, "planner": args.planner, "sets": results}
    if args.tabletop:
        out["tabletop"] = bench_tabletop(args.timeout, args.planner)
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print_table(results, systems)
        if args.tabletop:
            t = out["tabletop"]
            print(f"tabletop: {json.dumps({k: v for k, v in t.items() if k != 'rows'})}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
