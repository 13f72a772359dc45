"""Language coverage on an IPC collection: does every domain load, plan and validate?

ROOT is a folder laid out like Fast Downward's benchmark collection (aibasel/downward-benchmarks):
one subfolder per domain, problems beside ``domain.pddl`` or per-problem domain files
(``domain_p01.pddl``, ``p01-domain.pddl``; gsr.pddl.files.find_domain_file). For each domain one
problem (the smallest file, or the ``--pick``-th smallest) is parsed, planned with a short limit
and, when solved, validated with gsr.validate; with ``--fd``, Fast Downward (lama-first) runs on
the same files to tell the domains it accepts. Each domain runs in its own subprocess under a hard
wall limit, so a grounding that does not finish cannot stall the run.

Usage: python -m gsr.benchmarks.bench_ipc_language ROOT [--timeout 60] [--clock wall|cpu]
       [--planner lazy-ff] [--pick 0] [--fd] [--only a,b] [--save FILE] [--markdown]

``--clock cpu`` makes --timeout a CPU-time limit for each planner's own processes (GSR's child
process through RLIMIT_CPU, FD through its driver's --overall-time-limit, which is CPU time): on a
machine shared with other jobs a wall limit cuts both planners at a load-dependent point.

Columns: load (parsed), ground (GSR's grounding: wall seconds and ground operators, or "not
finished" within the limit), plan (solved / timeout / unsolvable / error / killed / crash), valid
(plan checked), GSR wall and CPU time of the whole child process (start-up, parse, ground, search,
validate), plan length; with --fd, FD's translator (wall seconds and operators from its log, or "not
finished"), status, wall and CPU time (its own processes) and plan length. A ROOT that does not exist is skipped with one line (exit 0): the collection is not shipped.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gsr.errors import GSRError
from gsr.pddl.files import find_domain_file
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import api
from gsr.validate import validate_plan


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


class CpuLimit(BaseException):
    """The child's CPU-time limit (``--clock cpu``) ran out (raised from the SIGXCPU handler)."""


def _on_sigxcpu(signum, frame):  # a signal handler
    # Once: past the soft limit the kernel sends SIGXCPU again every CPU-second, and a second one
    # during the first's unwinding (freeing a large task can take longer) would escape its handler.
    signal.signal(signal.SIGXCPU, signal.SIG_IGN)
    raise CpuLimit


def limit_cpu(seconds: float) -> None:
    """Stop this process's work after ``seconds`` of CPU time: SIGXCPU raises CpuLimit (the hard
    limit, 10 s later, kills a process stuck where Python cannot handle the signal)."""
    signal.signal(signal.SIGXCPU, _on_sigxcpu)
    soft = max(1, round(seconds))
    resource.setrlimit(resource.RLIMIT_CPU, (soft, soft + 10))


def run_one(
    domain_file: Path, problem_file: Path, timeout: float, planner: str = "lazy-ff", cpu: bool = False
) -> dict:
    """Parse, plan and validate in this process (called in a subprocess by ``main``); with ``cpu``
    the limit is on this process's CPU time (the planner's own wall deadline is set far out)."""
    row: dict = {"load": False, "plan": None, "valid": None, "length": None}
    start = time.perf_counter()
    if not cpu:
        _run_into(row, domain_file, problem_file, timeout, planner)
    else:
        limit_cpu(timeout)
        try:
            _run_into(row, domain_file, problem_file, 10 * timeout + 60, planner)
        except CpuLimit:
            row.update(plan="timeout", valid=None, length=None, message=f"over {timeout:g} s CPU")
    row["time"] = time.perf_counter() - start
    return row


def _run_into(row: dict, domain_file: Path, problem_file: Path, timeout: float, planner: str) -> None:
    """Fill ``row`` step by step, so that what was done survives a CPU-limit interruption."""
    try:
        domain = load_domain(domain_file)
        problem = load_problem(problem_file, domain)
    except GSRError as err:
        row["message"] = str(err)
        return
    row["load"] = True
    row["axioms"] = len(domain.axioms)
    ground = api.ground_task

    def recording(*args, **kwargs):  # the grounding's size as soon as it is known
        t0 = time.perf_counter()
        task = ground(*args, **kwargs)
        row["ground_time"], row["operators"] = time.perf_counter() - t0, len(task.ops)
        return task

    api.ground_task = recording
    try:
        result = api.plan(domain, problem, planner=planner, timeout=timeout)
    finally:
        api.ground_task = ground
    row["plan"] = result.status
    if result.status != "solved":
        row["message"] = result.message
    else:
        report = validate_plan(domain, problem, result.plan)
        row["valid"] = report.valid
        row["length"] = len(result.plan)
        if not report.valid:
            row["message"] = report.message


def run_fd(domain_file: Path, problem_file: Path, timeout: float, cpu: bool = False) -> dict:
    """Fast Downward lama-first on the files: status ('n/a' when it is not installed), wall and CPU
    time (FD's own processes: the driver, translator and search), plan length; with ``cpu`` the
    limit is FD's --overall-time-limit (CPU time) and the wall limit is far out."""
    from gsr.plan.fast_downward import run_fast_downward  # not in the GSR child, whose CPU is measured

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    details: dict = {}
    try:
        status, plan, _ = run_fast_downward(
            domain_file,
            problem_file,
            10 * timeout + 60 if cpu else timeout,
            memory_limit="4G",
            details=details,
            cpu_limit=timeout if cpu else None,
        )
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
    return {
        "status": status,
        "time": wall,
        "cpu": cpu,
        "length": len(plan) if plan is not None else None,
        **details,  # translated, translate_cpu / translate_wall, operators, axioms
    }


def subprocess_row(
    domain_file: Path, problem_file: Path, timeout: float, planner: str, cpu: bool = False
) -> dict:
    # Grounding is not interruptible: the wall limit is the subprocess's.
    hard = (10 if cpu else 3) * timeout + 60
    cmd = [sys.executable, __file__, "--one", str(domain_file), str(problem_file), "--timeout", str(timeout)]
    cmd += ["--planner", planner] + (["--clock", "cpu"] if cpu else [])
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


def _ground_cell(r: dict) -> str:
    """GSR's grounding: wall seconds and ground operators, or why there are none."""
    if r.get("operators") is not None:
        return f"{r.get('ground_time', 0):.2f} ({r['operators']})"
    return "not finished" if r.get("load") else "-"


def _translate_cell(f_: dict) -> str:
    """FD's translator: wall seconds and operators from its log, or 'not finished'."""
    if not f_ or f_.get("status") == "n/a":
        return "-"
    if not f_.get("translated"):
        return "not finished"
    return f"{f_.get('translate_wall', 0):.2f} ({f_.get('operators', '?')})"


def markdown(rows: list[dict], fd: bool) -> str:
    """The rows as a Markdown table (GSR's wall/CPU time are the whole child process: start-up,
    parse, ground, search and validation; the ground column is the grounding alone, wall seconds
    and ground operators; FD's translate column the same from its translator's log)."""
    head = "| domain | problem | load | GSR ground s (ops) | GSR plan | valid | GSR wall / CPU (s) | length |"
    rule = "|---|---|---|---:|---|---|---:|---:|"
    if fd:
        head += " FD translate s (ops) | FD lama-first | FD wall / CPU (s) | FD length |"
        rule += "---:|---|---:|---:|"
    out = [head, rule]
    for r in rows:
        t = f"{r.get('wall', r.get('time', 0)):.2f} / {r.get('cpu', 0):.2f}"
        line = (
            f"| {r['domain']} | {r['problem']} | {'yes' if r['load'] else 'no'} | {_ground_cell(r)} | "
            f"{r['plan']} | {'yes' if r['valid'] else '-' if r['valid'] is None else 'no'} | {t} | "
            f"{r.get('length') or '-'} |"
        )
        if fd:
            f_ = r.get("fd") or {}
            cpu = "-" if f_.get("cpu") is None else f"{f_['cpu']:.2f}"
            ft = f"{f_['time']:.2f} / {cpu}" if "time" in f_ else "-"
            line += f" {_translate_cell(f_)} | {f_.get('status')} | {ft} | {f_.get('length') or '-'} |"
        out.append(line)
    return "\n".join(out)


def summary(rows: list[dict], timeout: float, fd: bool) -> str:
    """Counts: domains that load, ground, plan and validate (and FD's translate / solve)."""
    n = len(rows)
    loaded = sum(bool(r["load"]) for r in rows)
    grounded = sum(r.get("operators") is not None for r in rows)
    solved = sum(r["plan"] == "solved" for r in rows)
    valid = sum(bool(r["valid"]) for r in rows)
    lines = [
        f"domains {n}: load {loaded}, ground {grounded}, plan {solved} (limit {timeout:g} s), validate {valid}"
    ]
    if fd:
        translated = sum(bool((r.get("fd") or {}).get("translated")) for r in rows)
        fd_solved = [r for r in rows if (r.get("fd") or {}).get("status") == "solved"]
        both = sum(r["plan"] == "solved" and bool(r["valid"]) for r in fd_solved)
        only_gsr = sum(
            r["plan"] == "solved" and bool(r["valid"]) and (r.get("fd") or {}).get("status") != "solved"
            for r in rows
        )
        lines.append(
            f"Fast Downward translated {translated}, solved {len(fd_solved)} of {n}; GSR solved and "
            f"validated {both} of those, and {only_gsr} FD did not solve"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path, nargs="?", help="folder with one subfolder per domain")
    parser.add_argument("--timeout", type=float, default=10.0, help="planner limit per problem (s)")
    parser.add_argument("--planner", default="lazy-ff", help="GSR planner (see gsr.plan.PLANNERS)")
    parser.add_argument("--pick", type=int, default=0, help="which problem by size (0: smallest)")
    parser.add_argument(
        "--clock",
        choices=("wall", "cpu"),
        default="wall",
        help="what --timeout limits: wall-clock seconds, or CPU seconds of each planner's own "
        "processes (GSR's child; FD's --overall-time-limit) - steadier on a loaded machine",
    )
    parser.add_argument("--fd", action="store_true", help="also run Fast Downward lama-first")
    parser.add_argument("--only", default="", help="comma-separated domain folders")
    parser.add_argument("--save", type=Path, help="write the rows as JSON")
    parser.add_argument(
        "--markdown", action="store_true", help="print the rows as a Markdown table at the end"
    )
    parser.add_argument("--one", nargs=2, type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(run_one(args.one[0], args.one[1], args.timeout, args.planner, args.clock == "cpu")))
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
            **subprocess_row(*files, args.timeout, args.planner, args.clock == "cpu"),
        }
        if args.fd:
            row["fd"] = run_fd(*files, args.timeout, args.clock == "cpu")
        rows.append(row)
        fd = f"  fd:{row['fd'].get('status')} {row['fd'].get('time', 0):.2f}s" if args.fd else ""
        msg = f"  {row.get('message', '')[:90]}" if row.get("message") else ""
        print(
            f"{folder.name:32} {files[1].name:24} load:{row['load']!s:5} plan:{row['plan']!s:10} "
            f"valid:{row['valid']!s:5} {row.get('wall', row.get('time', 0)):7.2f}s{fd}{msg}",
            flush=True,
        )
    print(summary(rows, args.timeout, args.fd))
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
