"""Instructions per tabletop ``plan()`` call under valgrind's callgrind (issue 18's stable metric).

Timings on the shared machine move by 20-40% with its load; instruction counts do not. This runs
the same Python process twice under ``valgrind --tool=callgrind`` (``PYTHONHASHSEED=0``): both build
the 30 generated tabletop-long tasks (seed 0) and make two warm-up ``plan()`` calls (the domain's
compiled grounding code and the C kernels are cached after the first); the second then plans all
30 tasks. The difference of the two totals over 30 is the figure:

    .venv/bin/python -m gsr.benchmarks.planner_callgrind [--tasks 30] [--ground-only]
    (cd /tmp/old && PYTHONPATH=/tmp/old /path/to/repo/.venv/bin/python -m gsr.benchmarks.planner_callgrind)

(another tree, unpacked with ``git archive``: run from its folder, since ``python -m`` puts the working
directory first on ``sys.path``; the output names the ``gsr.plan`` it counted)

``--ground-only`` counts ``ground_task`` instead of ``plan``. ``--ipc SET/PROBLEM.pddl`` counts one
grounding of that reference problem instead (its parsing subtracted). Needs ``valgrind`` on PATH.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import gsr.plan as gsr_plan
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan
from gsr.plan.grounding import ground_task

from .bench_planner import PDDL, tabletop_tasks


def _child(tasks: int, measured: bool, ground_only: bool, ipc: str | None) -> None:
    """The process valgrind runs: set-up and warm-up, then (``measured``) the counted calls."""
    if ipc:
        path = PDDL / ipc
        domain = load_domain(path.parent / "domain.pddl")
        problem = load_problem(path, domain)
        if measured:
            ground_task(domain, problem)
        return
    found = [(d, p) for _, d, p in tabletop_tasks("tabletop-long", tasks, 0)]
    for d, p in found[:2]:  # warm-up: compiled schemas, C kernels, caches of the domain
        plan(d, p)
    if not measured:
        return
    for d, p in found:
        if ground_only:
            ground_task(d, p)
        else:
            plan(d, p)


def _count(args: list[str], measured: bool) -> int:
    """Instructions (Ir) of one child run under callgrind."""
    with tempfile.TemporaryDirectory(prefix="gsr-callgrind-") as tmp:
        out = Path(tmp) / "callgrind.out"
        cmd = [
            "valgrind",
            "--tool=callgrind",
            f"--callgrind-out-file={out}",
            sys.executable,
            "-m",
            __spec__.name,
        ]
        cmd += [*args, "--child", "measured" if measured else "setup"]
        env = dict(os.environ, PYTHONHASHSEED="0")
        done = subprocess.run(cmd, capture_output=True, text=True, env=env)
        if done.returncode != 0:
            tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
            raise SystemExit(f"error: callgrind run failed: {tail}")
        found = re.search(r"^summary:\s+(\d+)", out.read_text(), re.M)
        if found is None:
            raise SystemExit("error: no instruction summary in callgrind's output")
        return int(found.group(1))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", type=int, default=30, help="tabletop-long tasks planned (seed 0)")
    ap.add_argument("--ground-only", action="store_true", help="count ground_task, not plan")
    ap.add_argument("--ipc", help="count one grounding of this reference problem (SET/FILE.pddl)")
    ap.add_argument("--child", choices=("setup", "measured"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        _child(args.tasks, args.child == "measured", args.ground_only, args.ipc)
        return 0
    if shutil.which("valgrind") is None:
        print("error: valgrind not found (apt-get install valgrind)", file=sys.stderr)
        return 2
    passed = [f"--tasks={args.tasks}"] + (["--ground-only"] if args.ground_only else [])
    passed += [f"--ipc={args.ipc}"] if args.ipc else []
    # Once outside valgrind first: byte-compiled modules and the C kernels then exist for both
    # counted runs (else the first would pay for writing them and the difference would not be the calls).
    warm = [sys.executable, "-m", __spec__.name, *passed, "--child", "setup"]
    if subprocess.run(warm, capture_output=True, env=dict(os.environ, PYTHONHASHSEED="0")).returncode != 0:
        print("error: the warm-up run failed", file=sys.stderr)
        return 2
    setup = _count(passed, measured=False)
    total = _count(passed, measured=True)
    calls = 1 if args.ipc else args.tasks
    what = f"ground_task({args.ipc})" if args.ipc else ("ground_task" if args.ground_only else "plan")
    print(f"gsr.plan from {Path(gsr_plan.__file__).parent}")
    print(f"set-up {setup / 1e6:.2f} M, with calls {total / 1e6:.2f} M instructions")
    print(f"{(total - setup) / calls / 1e6:.2f} M instructions per {what} call ({calls} calls)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
