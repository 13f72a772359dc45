"""Planner benchmark: GSR's planner vs pyperplan (GBFS + h_FF) vs Fast Downward lama-first.

Sets: the IPC sets in ../shared/data/pddl or tests/fixtures/pddl (blocks 35, gripper 20, miconic-simpleadl 30,
and in the reference folder the dev sets logistics00, satellite, rovers, zenotravel, driverlog,
elevators-sat08-strips, transport-sat08-strips, visitall-sat11-strips, tidybot-sat11-strips,
openstacks-sat08-adl), the 40 LIBERO tasks (``libero``) and seeded long GSR-Bench-style tabletop
tasks (``tabletop-long``). ``--pick 0.25,0.5`` runs only the problems at those fractions of each
IPC set's list (by size), for short side-by-side runs.

Usage: python benchmarks/bench_planner.py [--sets blocks,gripper,...] [--systems gsr,pyperplan,fd]
       [--timeout 60] [--clock wall|cpu] [--planner auto] [--long-tasks 30] [--seed 0] [--pick F,...]
       [--isolate] [--save FILE] [--markdown] [-v]
       python benchmarks/bench_planner.py --merge A.json B.json ... [--markdown]

GSR runs in-process; on IPC sets its time covers parsing, grounding and search, on tabletop sets it
is ``PlanResult.time`` (grounding + search; the problem is built from the scene graph beforehand).
With ``--isolate`` GSR runs each IPC problem in a fresh subprocess (a hard wall limit of 1.5 x the
timeout + 30 s, since grounding is not interruptible): its wall time runs from spawning the
interpreter to the plan, its CPU time is the child's own from its start (start-up and imports
included); FD's times are those of FD's own processes (driver, translator, search), as when FD is
run directly, not of the benchmark's child around it. Both report their peak resident memory (GSR's
read after planning, before validation; FD's the largest child process's ru_maxrss). Modules are
byte-compiled once first, as pip does on install, and the planner's C kernels (gsr.plan.relax_c) are
built once before the first task (as on any first use after an install).
``--clock cpu`` (implies ``--isolate``) makes ``--timeout`` a limit on CPU seconds of each system's own
processes, so that the comparison does not depend on the machine's load: GSR's child through
RLIMIT_CPU (counted from its start, interpreter and imports included; lifted once the plan is found,
so validation is never cut), FD through its driver's ``--overall-time-limit`` (CPU time of driver,
translator and search). A timeout counts the limit in the CPU column and its measured wall time in
the wall column; the hard wall limit of a child is then 10 x the timeout + 60 s.
pyperplan and Fast Downward run as subprocesses (interpreter start-up and FD's translator included),
with PYTHONHASHSEED=0. Every GSR plan, and with ``--isolate`` every FD plan, is checked with
gsr.validate.validate_plan after the clock stops (``validate_s``); an invalid plan counts as unsolved. pyperplan is STRIPS-only, so it is ``n/a`` on the ADL sets.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from gsr.errors import GSRError
from gsr.pddl.bddl import load_bddl
from gsr.pddl.files import find_domain_file
from gsr.pddl.model import And, Atom, Domain, Formula, Not, Problem
from gsr.pddl.parser import load_domain, load_problem
from gsr.pddl.writer import write_domain, write_problem
from gsr.plan import plan, relax_c
from gsr.resources import data_dir, load_builtin_domain, shared_data_dir

REPO = Path(__file__).resolve().parents[1]

# An isolated GSR run imports only what planning needs before its clock stops: the scene-graph modules
# (gsr.facts, gsr.libero, gsr.gsr_bench_format: pydantic, 0.2 s CPU) load inside the tabletop functions,
# the validator and the FD driver inside the functions that check plans and run FD.
if TYPE_CHECKING:
    from gsr.scene_graph import SceneGraph

# the IPC sets: the reference folder's pddl/ when present, else the same three sets shipped as test fixtures
PDDL = (
    shared_data_dir() / "pddl"
    if (shared_data_dir() / "pddl").is_dir()
    else Path(__file__).resolve().parents[1] / "tests" / "fixtures" / "pddl"
)
LIBERO = data_dir() / "libero"  # the 40 shipped LIBERO task files
IPC_SETS = (
    "blocks",
    "gripper",
    "miconic-simpleadl",
    "logistics00",
    "satellite",
    "rovers",
    "zenotravel",
    "driverlog",
    "elevators-sat08-strips",
    "transport-sat08-strips",
    "visitall-sat11-strips",
    "tidybot-sat11-strips",
    "openstacks-sat08-adl",
)
TABLETOP_SETS = ("libero", "tabletop-long")
SETS = IPC_SETS + TABLETOP_SETS
STRIPS_SETS = frozenset({"blocks", "gripper"})  # pyperplan handles STRIPS (+ typing) only
LONG = 10  # "long" tabletop task: a plan of at least this many steps
FD_MEMORY = "4G"  # the machine is shared; lama-first on the ADL tabletop tasks can grow past 7 GB


def _at(fractions: list[float], count: int) -> set[int]:
    """Indices of a list of ``count`` items at the given fractions of it."""
    return {min(int(f * count), count - 1) for f in fractions}


def problems(domain_set: str, pick: list[float] | None = None, skip: list[float] | None = None) -> list[Path]:
    """Problem files of one IPC set, in a natural order (by size, then name); with ``pick``, only
    those at the given fractions of that list (0.25: a quarter of the way down); with ``skip``, all
    but those (e.g. the problems earlier ``--pick`` runs measured)."""
    folder = PDDL / domain_set
    files = [p for p in folder.glob("*.pddl") if "domain" not in p.name]
    files.sort(key=lambda p: (len(p.stem), p.stem))
    if pick and files:
        files = [files[i] for i in sorted(_at(pick, len(files)))]
    if skip and files:
        dropped = _at(skip, len(files))
        files = [f for i, f in enumerate(files) if i not in dropped]
    return files


def _domain_of(problem: Path) -> Path:
    """The problem's domain file (domain.pddl or a per-problem one, by FD's conventions)."""
    found = find_domain_file(problem)
    if found is None:
        raise SystemExit(f"{problem}: no domain file beside it")
    return found


def _maxrss_mb(who: int) -> float:
    """Peak resident memory in MB of this process (RUSAGE_SELF) or its largest child."""
    return resource.getrusage(who).ru_maxrss / 1024.0


CLOCKS = ("wall", "cpu")


def hard_wall_limit(timeout: float, clock: str) -> float:
    """The wall-clock limit after which a child is killed (grounding is not interruptible)."""
    return 10 * timeout + 60 if clock == "cpu" else 1.5 * timeout + 30


def run_isolated(
    system: str, domain_file: Path, problem_file: Path, timeout: float, planner: str, clock: str = "wall"
) -> dict:
    """One system on one problem in a fresh subprocess that reports its row and peak memory.

    GSR's time runs from spawning its interpreter to the plan (start-up, imports, parsing, grounding,
    search; CPU from the child's own rusage); FD's is FD's own processes (driver, translator, search),
    as when it is run directly. Plan validation (both systems) comes after and is reported apart.
    ``clock`` says what ``timeout`` limits: wall seconds, or CPU seconds of the system's own processes."""
    cmd = [sys.executable, __file__, "--one", system, str(domain_file), str(problem_file)]
    cmd += ["--timeout", str(timeout), "--planner", planner, "--clock", clock]
    env = dict(os.environ, PYTHONHASHSEED="0", OMP_NUM_THREADS="1")
    hard = hard_wall_limit(timeout, clock)
    spawned = time.time()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=hard, env=env)
    except subprocess.TimeoutExpired:
        wall = hard if clock == "cpu" else timeout
        return {"status": "timeout", "time": wall, "cpu": timeout, "length": None, "killed": True}
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        elapsed = time.time() - spawned
        return {"status": "error", "time": elapsed, "cpu": elapsed, "length": None, "message": tail}
    row = json.loads(lines[-1])
    elapsed = row["done_at"] - spawned if "done_at" in row else row["time"]
    cpu = row.get("cpu_total", row["cpu"])
    if clock == "cpu":  # the limit is on CPU seconds; wall time is reported as measured
        if row["status"] == "timeout" or cpu > timeout:
            row = {**row, "status": "timeout", "length": None}
            cpu = timeout
        return {**row, "time": elapsed, "cpu": cpu}
    if row["status"] == "timeout" or elapsed > timeout:  # grounding past the limit is a timeout too
        row = {**row, "status": "timeout", "length": None}
        elapsed = cpu = timeout
    return {**row, "time": min(elapsed, timeout), "cpu": cpu}


class CpuLimit(BaseException):
    """This process's CPU-time limit (``--clock cpu``) ran out (raised from the SIGXCPU handler)."""


def _on_sigxcpu(signum, frame):  # a signal handler
    # Once: past the soft limit the kernel sends SIGXCPU again every CPU-second, and a second one
    # during the first's unwinding (freeing a large task can take longer) would escape its handler.
    signal.signal(signal.SIGXCPU, signal.SIG_IGN)
    raise CpuLimit


def limit_cpu(seconds: float) -> None:
    """Stop this process's work after ``seconds`` of CPU time (counted from its start): SIGXCPU
    raises CpuLimit. The hard limit stays unlimited so that lift_cpu_limit can lift the soft one
    (the parent's wall limit kills a child that never returns to Python)."""
    signal.signal(signal.SIGXCPU, _on_sigxcpu)
    soft = max(1, int(seconds + 0.999))
    resource.setrlimit(resource.RLIMIT_CPU, (soft, resource.RLIM_INFINITY))


def lift_cpu_limit() -> None:
    """No CPU limit any more (after the plan: its validation is not timed)."""
    resource.setrlimit(resource.RLIMIT_CPU, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))


def _one(
    system: str, domain_file: Path, problem_file: Path, timeout: float, planner: str, clock: str = "wall"
) -> dict:
    """The child side of run_isolated: the row plus peak memory (and, for GSR, when planning ended)."""
    if system == "gsr":
        if clock == "cpu":
            limit_cpu(timeout)
        row = run_gsr_files(domain_file, problem_file, timeout, planner, clock)
        return {**row, "peak_mb": row.get("plan_peak_mb", _maxrss_mb(resource.RUSAGE_SELF))}
    row = run_fd(domain_file, problem_file, timeout, validate=True, clock=clock)
    return {**row, "peak_mb": _maxrss_mb(resource.RUSAGE_CHILDREN)}


def _validated(row: dict, domain: Domain, problem: Problem, found) -> dict:
    """``row`` with the plan's length, or status 'invalid' (never count a wrong plan as solved);
    the check's wall time in ``validate_s``."""
    from gsr.validate import validate_plan

    start = time.perf_counter()
    report = validate_plan(domain, problem, found)
    row = {**row, "validate_s": time.perf_counter() - start}
    if not report.valid:
        return {**row, "status": "invalid", "length": None, "message": str(report)}
    return {**row, "length": len(found)}


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _gsr_row(
    domain: Domain,
    problem: Problem,
    timeout: float,
    planner: str,
    t0: float,
    cpu0: float | None = None,
    clock: str = "wall",
) -> dict:
    cpu0 = time.process_time() if cpu0 is None else cpu0
    if clock == "cpu":  # the CPU limit (limit_cpu) stops the search; its own wall deadline is far out
        try:
            result = plan(domain, problem, planner=planner, timeout=hard_wall_limit(timeout, clock))
        except CpuLimit:
            result = None
        lift_cpu_limit()
    else:
        result = plan(domain, problem, planner=planner, timeout=timeout)
    elapsed, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    if result is None:
        row = {"status": "timeout", "time": elapsed, "cpu": cpu, "length": None}
        row["message"] = f"over {timeout:g} s CPU"
    else:
        row = {"status": result.status, "time": elapsed, "cpu": cpu, "plan_time": result.time, "length": None}
    # When planning ended, this process's CPU since its start (interpreter and imports included) and
    # its peak memory, all read before validation (checking a 1,000-step plan has its own cost).
    usage = resource.getrusage(resource.RUSAGE_SELF)
    row.update(done_at=time.time(), cpu_total=usage.ru_utime + usage.ru_stime)
    row["plan_peak_mb"] = _maxrss_mb(resource.RUSAGE_SELF)
    if result is None:
        return row
    if result.plan is not None:
        row = _validated(row, domain, problem, result.plan)
    return {**row, "expanded": result.expanded}


def run_gsr_files(
    domain_file: Path, problem_file: Path, timeout: float, planner: str, clock: str = "wall"
) -> dict:
    """Parse, ground and search in-process; ``time`` is the wall time of all three. With ``clock``
    "cpu" the caller has set this process's CPU limit (limit_cpu)."""
    start, cpu0 = time.perf_counter(), time.process_time()
    try:
        domain = load_domain(domain_file)
        problem = load_problem(problem_file, domain)
        return _gsr_row(domain, problem, timeout, planner, start, cpu0, clock)
    except GSRError as err:
        t = time.perf_counter() - start
        return {
            "status": "error",
            "time": t,
            "cpu": time.process_time() - cpu0,
            "length": None,
            "message": str(err),
        }


def run_pyperplan(domain_file: Path, problem_file: Path, timeout: float) -> dict:
    """pyperplan -s gbf -H hff as a subprocess, on copies (it writes PROBLEM.soln beside the problem)."""
    with tempfile.TemporaryDirectory(prefix="gsr-pyperplan-") as tmp:
        dom = Path(tmp) / "domain.pddl"
        prob = Path(tmp) / problem_file.name
        shutil.copy(domain_file, dom)
        shutil.copy(problem_file, prob)
        cmd = [sys.executable, "-m", "pyperplan", "-s", "gbf", "-H", "hff", str(dom), str(prob)]
        env = dict(os.environ, PYTHONHASHSEED="0")
        start, cpu0 = time.perf_counter(), _children_cpu()
        try:
            subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, cwd=tmp)
        except subprocess.TimeoutExpired:
            return {"status": "timeout", "time": timeout, "cpu": timeout, "length": None}
        elapsed, cpu = time.perf_counter() - start, _children_cpu() - cpu0
        soln = prob.with_suffix(".pddl.soln")
        if not soln.is_file():
            return {"status": "unsolved", "time": elapsed, "cpu": cpu, "length": None}
        steps = [ln for ln in soln.read_text().splitlines() if ln.strip().startswith("(")]
        return {"status": "solved", "time": elapsed, "cpu": cpu, "length": len(steps)}


def run_fd(
    domain_file: Path, problem_file: Path, timeout: float, validate: bool = False, clock: str = "wall"
) -> dict:
    """Fast Downward --alias lama-first (driver, translator and search) as a subprocess; with
    ``validate``, its plan is checked like GSR's (after the clock stops). With ``clock`` "cpu" the
    limit is FD's --overall-time-limit (CPU seconds of its processes) and the wall limit far out."""
    from gsr.plan.fast_downward import run_fast_downward

    cpu_clock = clock == "cpu"
    start, cpu0 = time.perf_counter(), _children_cpu()
    try:
        status, found, message = run_fast_downward(
            domain_file,
            problem_file,
            hard_wall_limit(timeout, clock) if cpu_clock else timeout,
            memory_limit=FD_MEMORY,
            cpu_limit=timeout if cpu_clock else None,
        )
    except GSRError as err:
        return {"status": "n/a", "time": 0.0, "cpu": 0.0, "length": None, "message": str(err)}
    elapsed, cpu = time.perf_counter() - start, _children_cpu() - cpu0
    if cpu_clock:  # FD stops itself at its CPU limit (exit 21/23): reaped, so its wall time is known
        if status == "timeout" or cpu > timeout:
            status, found, cpu = "timeout", None, timeout
    elif status == "timeout":  # killed processes are not all reaped into RUSAGE_CHILDREN
        elapsed = cpu = timeout
    row = {
        "status": status,
        "time": elapsed if cpu_clock else min(elapsed, timeout),
        "cpu": cpu,
        "length": None,
    }
    if found is not None and validate:
        try:
            domain = load_domain(domain_file)
            row = _validated(row, domain, load_problem(problem_file, domain), found)
        except GSRError as err:
            row = {**row, "status": "invalid", "message": f"FD's plan cannot be checked: {err}"}
    elif found is not None:
        row["length"] = len(found)
    elif status == "error":
        row["message"] = message
    return row


# ------------------------------------------------------------------ long tabletop tasks

COLORS = ("red", "yellow", "blue", "green")
CABINET = "short_cabinet"
DRAWERS = (
    "drawer_high",
    "drawer_middle",
    "drawer_low",
)  # top to bottom: a lower one needs those above closed


def long_tabletop_task(seed: int) -> tuple[str, SceneGraph, Formula, int]:
    """One GSR-Bench-style task: (name, scene graph, goal, lower bound on its plan length >= 10).

    A table, a short cabinet with three drawers (each open or closed), three coloured boxes (some
    lidded and closed, some stacked on another box) and 5-9 cubes and mugs on the table, on boxes (mugs
    only: a GSR-Bench cube on a box can never be moved again), in boxes or in drawers. Goals: everything into the box of its colour with lids closed (``boxes``), one
    colour per drawer with every drawer closed (``drawers``), or cubes into boxes and mugs into the low
    drawer (``mixed``). The graph is built from GSR-Bench strings with graph_from_gsr_bench.
    """
    from gsr.gsr_bench_format import graph_from_gsr_bench

    rng = random.Random(seed)
    while True:  # redraw until at least 5 objects must move (each move is pick + place)
        kind = rng.choice(("boxes", "drawers", "mixed"))
        colors = rng.sample(COLORS, 3)
        nodes, edges = ["table", CABINET], [f"{CABINET}(on)table"]
        drawers = [f"{CABINET}/{d}" for d in DRAWERS]
        nodes += [f"{d}({rng.choice(('open', 'closed'))})" for d in drawers]
        boxes: dict[str, str] = {}
        for c in colors:
            lidded = rng.random() < 0.5
            boxes[c] = f"{c}_lidded_box" if lidded else f"{c}_box"
            nodes.append(
                boxes[c] + ("(closed)" if lidded and rng.random() < 0.7 else "(open)" if lidded else "")
            )
            below = [b for b in boxes.values() if b != boxes[c]]
            on_box = below and rng.random() < 0.25
            edges.append(f"{boxes[c]}(on){rng.choice(below) if on_box else 'table'}")
        objects: list[tuple[str, str]] = []
        count: dict[str, int] = {}
        for _ in range(rng.randint(5, 9)):
            c = rng.choice(colors)
            what = "mug" if rng.random() < 0.25 else "cube"
            count[c + what] = count.get(c + what, 0) + 1
            name = f"{c}_{what}{count[c + what]}"
            objects.append((name, c))
            nodes.append(name)
            r = rng.random()
            where = "on)table" if r < 0.6 else f"on){rng.choice(list(boxes.values()))}" if r < 0.7 else None
            if where is None:
                where = f"in){rng.choice(list(boxes.values()) + drawers)}"
            elif what == "cube" and where != "on)table":
                where = "in" + where[2:]  # GSR-Bench never lets a cube off a box it lies on: cubes go in
            edges.append(f"{name}({where}")
        goal, targets = [], {}
        for name, c in objects:
            if kind == "drawers":
                targets[name] = drawers[colors.index(c)]
            elif kind == "mixed" and "_mug" in name:
                targets[name] = drawers[2]
            else:
                targets[name] = boxes[c]
        goal = [Atom("in", (o, t)) for o, t in targets.items()]
        closed = drawers if kind != "boxes" else [b for b in boxes.values() if "lidded" in b]
        goal += [Not(Atom("open", (x,))) for x in closed]
        must_move = sum(f"{o}(in){t}" not in edges for o, t in targets.items())
        if must_move >= 5:
            graph = graph_from_gsr_bench({"nodes": nodes, "edges": edges})
            return f"long-{seed}-{kind}", graph, And(tuple(goal)), 2 * must_move


def long_tabletop_tasks(count: int, seed: int = 0) -> list[tuple[str, SceneGraph, Formula]]:
    """``count`` long tabletop tasks, deterministic in ``seed``."""
    return [long_tabletop_task(seed * 100_003 + i)[:3] for i in range(count)]


def tabletop_tasks(domain_set: str, count: int, seed: int) -> Iterator[tuple[str, Domain, Problem]]:
    """(name, domain, problem) of the LIBERO tasks or of the generated long tabletop tasks."""
    from gsr.facts import problem_from_graph
    from gsr.libero import libero_task

    domain = load_builtin_domain("tabletop")
    if domain_set == "libero":
        for bddl in sorted(LIBERO.rglob("*.bddl")):
            yield f"{bddl.parent.name}/{bddl.name}", domain, libero_task(load_bddl(bddl), domain)[1]
    else:
        for name, graph, goal in long_tabletop_tasks(count, seed):
            yield name, domain, problem_from_graph(graph, goal, name=name, domain=domain)


def bench_set(
    domain_set: str,
    systems: list[str],
    timeout: float,
    planner: str,
    verbose: bool,
    count: int,
    seed: int,
    pick: list[float] | None = None,
    isolate: bool = False,
    clock: str = "wall",
    skip: list[float] | None = None,
    on_row: Callable[[dict], None] | None = None,
) -> dict:
    """Run every system on every task of one set; per-task rows and per-system summaries. ``clock``
    "cpu" (IPC sets, isolated runs only) limits CPU seconds instead of wall seconds; ``on_row``
    receives the set's result so far after every task (for saving partial runs)."""
    rows = []
    if planner == "auto":  # FD runs lama-first on every set; GSR's tabletop planner is its default
        planner = "lama" if domain_set in IPC_SETS else "lazy-ff"
    if domain_set in IPC_SETS:
        tasks: Iterator = ((p.name, _domain_of(p), p) for p in problems(domain_set, pick, skip))
    else:
        tasks = tabletop_tasks(domain_set, count, seed)
    for name, dom, prob in tasks:
        row: dict = {"problem": name}
        with tempfile.TemporaryDirectory(prefix="gsr-bench-") as tmp:
            if isinstance(dom, Path):
                dom_file, prob_file = dom, prob
            else:  # tabletop: peers read the PDDL our writer emits (not timed)
                dom_file, prob_file = Path(tmp) / "domain.pddl", Path(tmp) / "problem.pddl"
                dom_file.write_text(write_domain(dom))
                prob_file.write_text(write_problem(prob))
            for system in systems:
                if isolate and isinstance(dom, Path) and system in ("gsr", "fd"):
                    row[system] = run_isolated(system, dom_file, prob_file, timeout, planner, clock)
                elif system == "gsr":
                    if isinstance(dom, Path):
                        row[system] = run_gsr_files(dom_file, prob_file, timeout, planner)
                    else:
                        row[system] = _gsr_row(dom, prob, timeout, planner, time.perf_counter(), None)
                elif system == "pyperplan":
                    if domain_set in STRIPS_SETS:
                        row[system] = run_pyperplan(dom_file, prob_file, timeout)
                    else:
                        row[system] = {"status": "n/a", "time": 0.0, "cpu": 0.0, "length": None}
                elif system == "fd":
                    row[system] = run_fd(dom_file, prob_file, timeout)
                else:
                    raise SystemExit(f"unknown system {system!r}; choose from gsr, pyperplan, fd")
        if verbose:
            cells = "  ".join(
                f"{s}:{row[s]['status']}/{row[s]['time']:.3f}s/{row[s].get('cpu', 0):.3f}cpu/{row[s]['length']}"
                for s in systems
            )
            print(f"{domain_set}/{name}: {cells}", file=sys.stderr, flush=True)
        rows.append(row)
        if on_row is not None:
            on_row({"set": domain_set, "timeout": timeout, "clock": clock, "planner": planner, "rows": rows})
    return {"set": domain_set, "timeout": timeout, "clock": clock, "planner": planner, "rows": rows}


def summarize(result: dict, system: str) -> dict:
    """Coverage, total wall/CPU time (unsolved tasks count their time, timeouts the limit), lengths."""
    cells = [r[system] for r in result["rows"] if system in r]
    if not cells or all(c["status"] == "n/a" for c in cells):
        return {"coverage": None}
    solved = [c for c in cells if c["status"] == "solved"]
    long = [c for c in solved if c["length"] >= LONG]
    return {
        "coverage": len(solved),
        "tasks": len(cells),
        "total_time": sum(c["time"] for c in cells),
        "total_cpu": sum(c.get("cpu", c["time"]) for c in cells),
        "total_length": sum(c["length"] for c in solved),
        "median_time": statistics.median(c["time"] for c in cells),
        "median_cpu": statistics.median(c.get("cpu", c["time"]) for c in cells),
        "long_tasks": len(long),
        "median_time_long": statistics.median(c["time"] for c in long) if long else None,
        "median_cpu_long": statistics.median(c.get("cpu", c["time"]) for c in long) if long else None,
        "peak_mb": max((c["peak_mb"] for c in cells if c.get("peak_mb") is not None), default=None),
    }


def _systems(result: dict) -> list[str]:
    seen: list[str] = []
    for row in result["rows"]:
        seen += [k for k in row if k != "problem" and k not in seen]
    return seen


HEAD = [
    "set",
    "system",
    "coverage",
    "wall (s)",
    "CPU (s)",
    "plan length",
    "wall / FD",
    "CPU / FD",
    "median wall / CPU (ms)",
    "peak MB",
]


def _row(label: str, system: str, s: dict, fd: dict, median: str) -> list[str]:
    """One table row: coverage, totals, ratios to Fast Downward (when it ran), medians, peak memory."""
    ok = fd["coverage"] is not None
    return [
        label,
        system,
        str(s["coverage"]),
        f"{s['total_time']:.2f}",
        f"{s['total_cpu']:.2f}",
        str(s["total_length"]),
        f"{s['total_time'] / fd['total_time']:.2f}" if ok else "",
        f"{s['total_cpu'] / fd['total_cpu']:.2f}" if ok else "",
        median,
        "" if s["peak_mb"] is None else f"{s['peak_mb']:.0f}",
    ]


def table_lines(results: list[dict]) -> list[list[str]]:
    """One row per set and system: coverage, totals, ratios to Fast Downward, medians."""
    lines = []
    for res in results:
        fd = summarize(res, "fd")
        for system in _systems(res):
            s = summarize(res, system)
            if s["coverage"] is None:
                lines.append([res["set"], system, "n/a"] + [""] * (len(HEAD) - 3))
                continue
            median = f"{s['median_time'] * 1000:.1f} / {s['median_cpu'] * 1000:.1f}"
            if s["long_tasks"] and res["set"] in TABLETOP_SETS:
                median += (
                    f"; {s['long_tasks']} solved with >= {LONG} steps: "
                    f"{s['median_time_long'] * 1000:.1f} / {s['median_cpu_long'] * 1000:.1f}"
                )
            lines.append(_row(f"{res['set']} ({s['tasks']})", system, s, fd, median))
    ipc = [r for r in results if r["set"] in IPC_SETS]
    if len(ipc) > 1:  # all IPC sets together: the side-by-side totals
        merged = {"set": "IPC total", "rows": [row for r in ipc for row in r["rows"]]}
        fd = summarize(merged, "fd")
        for system in _systems(merged):
            s = summarize(merged, system)
            if s["coverage"] is not None:
                median = f"{s['median_time'] * 1000:.1f} / {s['median_cpu'] * 1000:.1f}"
                lines.append(_row(f"all IPC sets ({s['tasks']})", system, s, fd, median))
    return lines


def print_table(results: list[dict], markdown: bool) -> None:
    """Print the summary table, aligned text or Markdown."""
    lines = table_lines(results)
    if markdown:
        print("| " + " | ".join(HEAD) + " |")
        print("|" + "|".join("---" if i < 2 else "---:" for i in range(len(HEAD))) + "|")
        for line in lines:
            print("| " + " | ".join(line) + " |")
        return
    widths = [max(len(x[i]) for x in [HEAD, *lines]) for i in range(len(HEAD))]
    for line in [HEAD, *lines]:
        cells = zip(line, widths, strict=True)
        print("  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(cells)))


def failures(results: list[dict]) -> list[str]:
    """Per set, the problems some system did not solve: ``set: problem (system status, ...)``."""
    lines = []
    for res in results:
        for row in res["rows"]:
            cells = {k: v for k, v in row.items() if k != "problem" and v.get("status") != "n/a"}
            if any(c["status"] != "solved" for c in cells.values()):
                what = ", ".join(f"{k} {c['status']}" for k, c in cells.items())
                lines.append(f"{res['set']}: {row['problem']} ({what})")
    return lines


def merge(results: list[dict]) -> list[dict]:
    """Combine saved runs (e.g. peers run set by set): rows of the same set are joined by task name."""
    by_set: dict[str, dict] = {}
    for res in results:
        cur = by_set.setdefault(res["set"], {"set": res["set"], "rows": []})
        index = {r["problem"]: r for r in cur["rows"]}
        for row in res["rows"]:
            if row["problem"] not in index:
                index[row["problem"]] = {"problem": row["problem"]}
                cur["rows"].append(index[row["problem"]])
            index[row["problem"]].update(row)
    order = {s: i for i, s in enumerate(SETS)}
    return sorted(by_set.values(), key=lambda r: order.get(r["set"], len(order)))


def save(path: Path, data: object) -> None:
    """Write JSON atomically (temp file + rename)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "w") as fh:
        json.dump(data, fh, indent=1)
    os.replace(tmp, path)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", default=",".join(SETS), help=f"comma-separated, from {', '.join(SETS)}")
    parser.add_argument("--systems", default="gsr,pyperplan,fd", help="comma-separated: gsr, pyperplan, fd")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per task and system")
    parser.add_argument(
        "--clock",
        choices=CLOCKS,
        default="wall",
        help="what --timeout limits on the IPC sets: wall seconds, or CPU seconds of each system's own "
        "processes (cpu implies --isolate; wall time is reported either way)",
    )
    parser.add_argument(
        "--planner",
        default="auto",
        help="GSR planner (see gsr.plan.PLANNERS); auto: lama on the IPC sets (as FD's lama-first), "
        "lazy-ff (gsr's default) on the tabletop sets",
    )
    parser.add_argument("--long-tasks", type=int, default=30, help="number of generated long tabletop tasks")
    parser.add_argument("--seed", type=int, default=0, help="seed of the long tabletop task generator")
    parser.add_argument("--save", type=Path, help="write the full per-task results as JSON")
    parser.add_argument("--merge", type=Path, nargs="+", help="print the table of saved runs instead")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    parser.add_argument(
        "--failures", action="store_true", help="with --merge: list the problems some system did not solve"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="one line per task on stderr")
    parser.add_argument("--pick", default="", help="fractions of each IPC set's list, e.g. 0.25,0.5")
    parser.add_argument(
        "--skip-pick", default="", help="leave out the problems at these fractions (those --pick F,... ran)"
    )
    parser.add_argument(
        "--isolate", action="store_true", help="GSR and FD in fresh subprocesses, peak memory reported"
    )
    parser.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        system, dom, prob = args.one
        print(json.dumps(_one(system, Path(dom), Path(prob), args.timeout, args.planner, args.clock)))
        return 0
    if args.merge:
        try:
            loaded = [json.loads(p.read_text()) for p in args.merge]
        except (OSError, json.JSONDecodeError) as err:
            parser.error(f"cannot read saved results: {err}")
        merged = merge([s for d in loaded for s in d["sets"]])
        print_table(merged, args.markdown)
        if args.failures:
            print("\n".join(["", "Not solved by every system:", *failures(merged)]))
        return 0
    systems = [s for s in args.systems.split(",") if s]
    sets = [s for s in args.sets.split(",") if s]
    unknown = [s for s in sets if s not in SETS] + [s for s in systems if s not in ("gsr", "pyperplan", "fd")]
    if unknown:
        parser.error(
            f"unknown set(s)/system(s) {unknown}; sets: {', '.join(SETS)}; systems: gsr, pyperplan, fd"
        )
    pick = [float(f) for f in args.pick.split(",") if f] if args.pick else None
    if args.clock == "cpu":  # a CPU limit needs each system in its own processes
        args.isolate = True
    if args.isolate:  # byte-compile once, as pip does on install (else every child recompiles edited modules)
        import compileall

        for folder in ("gsr", "skills", "perception", "benchmarks"):
            if (REPO / folder).is_dir():
                compileall.compile_dir(REPO / folder, quiet=1)
    # the planner's C kernels are built once per installation (first use), not per task
    if "gsr" in systems and relax_c.library() is None and relax_c.allowed():
        print(f"note: planner C kernels unavailable ({relax_c.why_not}); numba or Python", file=sys.stderr)
    skip = [float(f) for f in args.skip_pick.split(",") if f] if args.skip_pick else None
    results: list[dict] = []

    def partial(current: dict) -> None:  # with --save, the file holds every finished task
        if args.save:
            save(args.save, {"argv": sys.argv[1:], "partial": True, "sets": [*results, current]})

    for s in sets:
        results.append(
            bench_set(
                s,
                systems,
                args.timeout,
                args.planner,
                args.verbose,
                args.long_tasks,
                args.seed,
                pick,
                args.isolate,
                args.clock,
                skip,
                partial,
            )
        )
    if args.save:
        save(args.save, {"argv": sys.argv[1:], "sets": results})
    print_table(results, args.markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
