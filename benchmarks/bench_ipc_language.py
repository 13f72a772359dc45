"""Language coverage on an IPC collection: does every domain load, plan and validate?

ROOT is a folder laid out like Fast Downward's benchmark collection (aibasel/downward-benchmarks):
one subfolder per domain, problems beside ``domain.pddl`` or per-problem domain files
(``domain_p01.pddl``, ``p01-domain.pddl``; gsr.pddl.files.find_domain_file). For each domain one
problem (the smallest file, or the ``--pick``-th smallest) is parsed, planned with a short limit
and, when solved, validated with gsr.validate; with ``--fd``, Fast Downward (lama-first) runs on
the same files to tell the domains it accepts. Each domain runs in its own subprocess under a hard
wall limit, so a grounding that does not finish cannot stall the run.

Usage: python benchmarks/bench_ipc_language.py ROOT [--timeout 10] [--planner lazy-ff] [--pick 0] [--fd] [--only a,b]
       [--save FILE]

Columns: load (parsed), plan (solved / timeout / unsolvable / error), valid (plan checked), time
(parse + ground + search + validate, wall), fd (FD's status when --fd).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from gsr.pddl.files import find_domain_file  # noqa: E402


def pick_problem(folder: Path, pick: int) -> tuple[Path, Path] | None:
    """(domain file, problem file) of the ``pick``-th smallest problem with a domain file."""
    found = []
    for p in folder.glob("*.pddl"):
        if "domain" in p.name:
            continue
        dom = find_domain_file(p)
        if dom is not None:
            found.append((p.stat().st_size, p.name, dom, p))
    found.sort()
    if not found:
        return None
    _, _, dom, prob = found[min(pick, len(found) - 1)]
    return dom, prob


def run_one(domain_file: Path, problem_file: Path, timeout: float, planner: str = "lazy-ff") -> dict:
    """Parse, plan and validate in this process (called in a subprocess by ``main``)."""
    from gsr.errors import GSRError
    from gsr.pddl.parser import load_domain, load_problem
    from gsr.plan import plan
    from gsr.validate import validate_plan

    row: dict = {"load": False, "plan": None, "valid": None, "length": None}
    start = time.perf_counter()
    try:
        domain = load_domain(domain_file)
        problem = load_problem(problem_file, domain)
    except GSRError as err:
        return {**row, "message": str(err), "time": time.perf_counter() - start}
    row["load"] = True
    row["axioms"] = len(domain.axioms)
    result = plan(domain, problem, planner=planner, timeout=timeout)
    row["plan"] = result.status
    row["ground_time"] = result.ground_time
    if result.status != "solved":
        row["message"] = result.message
    else:
        report = validate_plan(domain, problem, result.plan)
        row["valid"] = report.valid
        row["length"] = len(result.plan)
        if not report.valid:
            row["message"] = report.message
    row["time"] = time.perf_counter() - start
    return row


def run_fd(domain_file: Path, problem_file: Path, timeout: float) -> str:
    """Fast Downward lama-first's status on the files ('n/a' when it is not installed)."""
    from gsr.errors import GSRError
    from gsr.plan.fast_downward import run_fast_downward

    try:
        return run_fast_downward(domain_file, problem_file, timeout, memory_limit="4G")[0]
    except GSRError:
        return "n/a"


def _subprocess_row(domain_file: Path, problem_file: Path, timeout: float, planner: str) -> dict:
    hard = 3 * timeout + 60  # grounding is not interruptible: the wall limit is the subprocess's
    cmd = [sys.executable, __file__, "--one", str(domain_file), str(problem_file), "--timeout", str(timeout)]
    cmd += ["--planner", planner]
    env = dict(os.environ, PYTHONHASHSEED="0", OMP_NUM_THREADS="1")
    start = time.perf_counter()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=hard, env=env)
    except subprocess.TimeoutExpired:
        return {"load": None, "plan": "killed", "valid": None, "time": hard, "message": f"over {hard:g} s"}
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {
            "load": None,
            "plan": "crash",
            "valid": None,
            "time": time.perf_counter() - start,
            "message": tail,
        }
    return json.loads(lines[-1])


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path, nargs="?", help="folder with one subfolder per domain")
    parser.add_argument("--timeout", type=float, default=10.0, help="planner limit per problem (s)")
    parser.add_argument("--planner", default="lazy-ff", help="GSR planner (see gsr.plan.PLANNERS)")
    parser.add_argument("--pick", type=int, default=0, help="which problem by size (0: smallest)")
    parser.add_argument("--fd", action="store_true", help="also run Fast Downward lama-first")
    parser.add_argument("--only", default="", help="comma-separated domain folders")
    parser.add_argument("--save", type=Path, help="write the rows as JSON")
    parser.add_argument("--one", nargs=2, type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(run_one(args.one[0], args.one[1], args.timeout, args.planner)))
        return 0
    if args.root is None or not args.root.is_dir():
        parser.error("ROOT must be a folder with one subfolder per domain")
    only = {s for s in args.only.split(",") if s}
    rows = []
    for folder in sorted(p for p in args.root.iterdir() if p.is_dir()):
        if only and folder.name not in only:
            continue
        files = pick_problem(folder, args.pick)
        if files is None:
            continue
        row = {
            "domain": folder.name,
            "problem": files[1].name,
            **_subprocess_row(*files, args.timeout, args.planner),
        }
        if args.fd:
            row["fd"] = run_fd(*files, args.timeout)
        rows.append(row)
        fd = f"  fd:{row['fd']}" if args.fd else ""
        msg = f"  {row.get('message', '')[:90]}" if row.get("message") else ""
        print(
            f"{folder.name:32} {files[1].name:24} load:{row['load']!s:5} plan:{row['plan']!s:10} "
            f"valid:{row['valid']!s:5} {row.get('time', 0):7.2f}s{fd}{msg}",
            flush=True,
        )
    n = len(rows)
    loaded = sum(bool(r["load"]) for r in rows)
    solved = sum(r["plan"] == "solved" for r in rows)
    valid = sum(bool(r["valid"]) for r in rows)
    print(f"domains {n}: load {loaded}, plan {solved} (limit {args.timeout:g} s), validate {valid}")
    if args.fd:
        print(f"Fast Downward solved {sum(r.get('fd') == 'solved' for r in rows)} of {n}")
    if args.save:
        fd_, tmp = tempfile.mkstemp(prefix=f".{args.save.name}.", dir=args.save.parent)
        with os.fdopen(fd_, "w") as fh:
            json.dump({"argv": sys.argv[1:], "rows": rows}, fh, indent=1)
        os.replace(tmp, args.save)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
