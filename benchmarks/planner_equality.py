"""Same-output check for planner changes (issue 18): grounding hashes and plans step by step.

Grounds the 30 generated tabletop-long tasks (seed 0), the 40 shipped LIBERO tasks and 14 IPC dev
problems, and records per problem a SHA-256 of the ground task (atoms, operators with their
conditional effects, axioms, initial state and goal DNF) with its operator and atom counts, and one
of its delete relaxation's unary operators (``Relaxation``, unit costs); plans
the 70 tabletop/LIBERO tasks with ``lazy-ff`` and records each plan's steps and expansions. Run it
with two trees and compare the files:

    git archive OLD | tar -x -C /tmp/old     # the other tree, unpacked
    (cd /tmp/old && GSR_SHARED_DATA=$PWD/../shared/data PYTHONPATH=/tmp/old \
        /path/to/repo/.venv/bin/python -m gsr.benchmarks.planner_equality --out /tmp/old.json)
    .venv/bin/python -m gsr.benchmarks.planner_equality --out /tmp/new.json --compare /tmp/old.json

Run the other tree's command *from that tree's folder*: ``python -m`` puts the working directory first
on ``sys.path``, so run from this repository the command checks this tree whatever ``PYTHONPATH`` says
(the first output line names the ``gsr.plan`` it used). Set ``GSR_SHARED_DATA`` there, as the reference
folder is found relative to the working directory. This module only uses the public ``ground_task`` and
``plan``. ``--compare`` exits 1 and names the problems that differ.
``GSR_GROUND_COMPILED=0`` checks the general grounding path. The IPC problems are those of
docs/performance.md's grounding passes; a missing reference folder skips them with a note.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

import gsr.plan as gsr_plan
from gsr.errors import GSRError
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation

from .bench_planner import PDDL, tabletop_tasks

IPC_PROBLEMS = (
    ("blocks", "probBLOCKS-10-0.pddl"),
    ("miconic-simpleadl", "s5-0.pddl"),
    ("miconic-simpleadl", "s6-0.pddl"),
    ("openstacks-sat08-adl", "p05.pddl"),
    ("logistics00", "probLOGISTICS-10-0.pddl"),
    ("rovers", "p10.pddl"),
    ("elevators-sat08-strips", "p05.pddl"),
    ("driverlog", "p10.pddl"),
    ("tidybot-sat11-strips", "p01.pddl"),
    ("satellite", "p05-pfile5.pddl"),
    ("zenotravel", "p05.pddl"),
    ("gripper", "prob05.pddl"),
    ("transport-sat08-strips", "p05.pddl"),
    ("visitall-sat11-strips", "problem12.pddl"),
)


def task_digest(task) -> dict:
    """SHA-256 of everything a ground task hands the search, with its sizes."""
    h = hashlib.sha256()
    h.update(repr([(a.predicate, a.args) for a in task.atoms]).encode())
    for group in (task.ops, task.axioms):
        h.update(b"|")
        for o in group:
            h.update(repr((o.name, o.args, o.cost, o.pre, o.neg, o.add, o.delete, o.cond)).encode())
    h.update(repr((task.init, task.goals, list(task.axiom_strata))).encode())
    return {"hash": h.hexdigest(), "operators": len(task.ops), "atoms": len(task.atoms)}


def relaxation_digest(task) -> str:
    """SHA-256 of the unary operators the delete relaxation builds for ``task`` (unit costs, as the
    greedy planners use): facts, preconditions, adds, costs, owners, complements."""
    relax = Relaxation(task, unit=True)
    h = hashlib.sha256()
    h.update(repr((relax.n_facts, sorted(relax.comp.items()), relax.goal_stop)).encode())
    h.update(repr((relax.pre, relax.add, relax.cost, relax.owner)).encode())
    return h.hexdigest()


def problems(ipc: bool = True):
    """(set, name, domain, problem) of the checked problems."""
    for domain_set in ("tabletop-long", "libero"):
        for name, domain, problem in tabletop_tasks(domain_set, 30, 0):
            yield domain_set, name, domain, problem
    if not ipc:
        return
    for domain_set, name in IPC_PROBLEMS:
        path = PDDL / domain_set / name
        if not path.is_file():
            print(f"note: {path} missing, skipped", file=sys.stderr)
            continue
        domain = load_domain(PDDL / domain_set / "domain.pddl")
        yield domain_set, name, domain, load_problem(path, domain)


def collect(ipc: bool = True, plans: bool = True) -> dict:
    """Digests of every problem's grounding and the tabletop/LIBERO plans."""
    out: dict = {"grounding": {}, "plans": {}}
    for domain_set, name, domain, problem in problems(ipc):
        key = f"{domain_set}/{name}"
        start = time.process_time()
        task = ground_task(domain, problem)
        cpu = round(time.process_time() - start, 3)
        out["grounding"][key] = {**task_digest(task), "relaxation": relaxation_digest(task), "cpu_s": cpu}
        if plans and domain_set in ("tabletop-long", "libero"):
            result = plan(domain, problem, planner="lazy-ff", timeout=60)
            steps = [str(s) for s in result.plan.steps] if result.plan is not None else None
            out["plans"][key] = {"status": result.status, "expanded": result.expanded, "steps": steps}
    return out


def compare(new: dict, old: dict) -> list[str]:
    """Lines naming what differs between two collected files (empty: equal)."""
    diff = []
    for part in ("grounding", "plans"):
        for key in sorted(set(new[part]) | set(old[part])):
            a, b = new[part].get(key), old[part].get(key)
            if a is None or b is None:
                diff.append(f"{part} {key}: only in {'old' if a is None else 'new'}")
                continue
            a = {k: v for k, v in a.items() if k != "cpu_s"}
            b = {k: v for k, v in b.items() if k != "cpu_s"}
            if a != b:
                diff.append(f"{part} {key}: differs")
    return diff


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="where to write the digests (JSON)")
    ap.add_argument("--compare", type=Path, help="a file written by another tree: exit 1 when they differ")
    ap.add_argument("--no-ipc", action="store_true", help="only the 70 tabletop/LIBERO tasks")
    ap.add_argument("--no-plans", action="store_true", help="grounding digests only")
    args = ap.parse_args(argv)
    try:
        found = collect(ipc=not args.no_ipc, plans=not args.no_plans)
    except GSRError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    args.out.write_text(json.dumps(found, indent=1))
    steps = sum(len(p["steps"] or ()) for p in found["plans"].values())
    expanded = sum(p["expanded"] for p in found["plans"].values())
    ops = sum(g["operators"] for g in found["grounding"].values())
    print(f"gsr.plan from {Path(gsr_plan.__file__).parent}")
    print(
        f"{len(found['grounding'])} groundings ({ops} operators), {len(found['plans'])} plans "
        f"({steps} steps, {expanded} expansions) -> {args.out}"
    )
    if args.compare:
        try:
            old = json.loads(args.compare.read_text())
        except (OSError, ValueError) as err:
            print(f"error: cannot read {args.compare}: {err}", file=sys.stderr)
            return 2
        diff = compare(found, old)
        for line in diff:
            print(line)
        print("equal" if not diff else f"{len(diff)} differences")
        return 1 if diff else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
