"""Language coverage on an IPC collection: does every domain load, plan and validate?

ROOT is a folder laid out like Fast Downward's benchmark collection (aibasel/downward-benchmarks):
one subfolder per domain, problems beside ``domain.pddl`` or per-problem domain files
(``domain_p01.pddl``, ``p01-domain.pddl``; gsr.pddl.files.find_domain_file). For each domain one
problem (the smallest file, or the ``--pick``-th smallest) is parsed, planned with a short limit
and, when solved, validated with gsr.validate; with ``--fd``, Fast Downward (lama-first) runs on
the same files to tell the domains it accepts. Each domain runs in its own subprocess under a hard
wall limit, so a grounding that does not finish cannot stall the run.

Usage: python -m gsr.benchmarks.bench_ipc_language ROOT [--timeout 60] [--planner lazy-ff] [--pick 0]
       [--fd] [--only a,b] [--save FILE] [--markdown]

Columns: load (parsed), plan (solved / timeout / unsolvable / error / killed / crash), valid (plan
checked), GSR wall and CPU time of the whole child process (start-up, parse, ground, search,
validate), plan length; with --fd, FD's status, wall and CPU time (its own processes) and plan
length. A ROOT that does not exist is skipped with one line (exit 0): the collection is not shipped.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
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


def run_fd(domain_file: Path, problem_file: Path, timeout: float) -> dict:
    """Fast Downward lama-first on the files: status ('n/a' when it is not installed), wall and CPU
    time (FD's own processes: the driver, translator and search), plan length."""
    from gsr.errors import GSRError
    from gsr.plan.fast_downward import run_fast_downward

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    try:
        status, plan, _ = run_fast_downward(domain_file, problem_file, timeout, memory_limit="4G")
    except GSRError:
        return {"status": "n/a"}
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # A run killed at the limit is not reaped into our usage (its driver dies with the translator
    # or search under it): its CPU time is unknown, not near zero.
    cpu = (
        None
        if status == "timeout"
        else (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    )
    return {"status": status, "time": wall, "cpu": cpu, "length": len(plan) if plan is not None else None}


def _subprocess_row(domain_file: Path, problem_file: Path, timeout: float, planner: str) -> dict:
    hard = 3 * timeout + 60  # grounding is not interruptible: the wall limit is the subprocess's
    cmd = [sys.executable, __file__, "--one", str(domain_file), str(problem_file), "--timeout", str(timeout)]
    cmd += ["--planner", planner]
    env = dict(os.environ, PYTHONHASHSEED="0", OMP_NUM_THREADS="1")
    start = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
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
    row = json.loads(lines[-1])
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    row["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    row["wall"] = time.perf_counter() - start
    return row


def markdown(rows: list[dict], fd: bool) -> str:
    """The rows as a Markdown table (GSR's wall/CPU time are the whole child process: start-up,
    parse, ground, search and validation)."""
    head = "| domain | problem | load | GSR plan | valid | GSR wall / CPU (s) | length |"
    rule = "|---|---|---|---|---|---:|---:|"
    if fd:
        head += " FD lama-first | FD wall / CPU (s) | FD length |"
        rule += "---|---:|---:|"
    out = [head, rule]
    for r in rows:
        t = f"{r.get('wall', r.get('time', 0)):.2f} / {r.get('cpu', 0):.2f}"
        line = (
            f"| {r['domain']} | {r['problem']} | {'yes' if r['load'] else 'no'} | {r['plan']} | "
            f"{'yes' if r['valid'] else '-' if r['valid'] is None else 'no'} | {t} | {r.get('length') or '-'} |"
        )
        if fd:
            f_ = r.get("fd") or {}
            cpu = "-" if f_.get("cpu") is None else f"{f_['cpu']:.2f}"
            ft = f"{f_['time']:.2f} / {cpu}" if "time" in f_ else "-"
            line += f" {f_.get('status')} | {ft} | {f_.get('length') or '-'} |"
        out.append(line)
    return "\n".join(out)


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
    parser.add_argument(
        "--markdown", action="store_true", help="print the rows as a Markdown table at the end"
    )
    parser.add_argument("--one", nargs=2, type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(run_one(args.one[0], args.one[1], args.timeout, args.planner)))
        return 0
    if args.root is None:
        parser.error("give ROOT, a folder with one subfolder per domain")
    if not args.root.is_dir():  # the collection is not shipped (licences vary): nothing to measure
        print(f"skipped: {args.root} is not a folder (fetch the collection first, see docs/planner.md)")
        return 0
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
        fd = f"  fd:{row['fd'].get('status')} {row['fd'].get('time', 0):.2f}s" if args.fd else ""
        msg = f"  {row.get('message', '')[:90]}" if row.get("message") else ""
        print(
            f"{folder.name:32} {files[1].name:24} load:{row['load']!s:5} plan:{row['plan']!s:10} "
            f"valid:{row['valid']!s:5} {row.get('wall', row.get('time', 0)):7.2f}s{fd}{msg}",
            flush=True,
        )
    n = len(rows)
    loaded = sum(bool(r["load"]) for r in rows)
    solved = sum(r["plan"] == "solved" for r in rows)
    valid = sum(bool(r["valid"]) for r in rows)
    print(f"domains {n}: load {loaded}, plan {solved} (limit {args.timeout:g} s), validate {valid}")
    if args.fd:
        fd_solved = [r for r in rows if r["fd"].get("status") == "solved"]
        both = sum(r["plan"] == "solved" and bool(r["valid"]) for r in fd_solved)
        print(f"Fast Downward solved {len(fd_solved)} of {n}; GSR solved and validated {both} of those")
    if args.markdown:
        print(markdown(rows, args.fd))
    if args.save:
        fd_, tmp = tempfile.mkstemp(prefix=f".{args.save.name}.", dir=args.save.parent)
        with os.fdopen(fd_, "w") as fh:
            json.dump({"argv": sys.argv[1:], "rows": rows}, fh, indent=1)
        os.replace(tmp, args.save)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
