"""Mean plan length per GSR-Bench cell: best-found (lazy-ff) lengths, certified optimal where they meet a bound.

Usage: python benchmarks/bench_gsr_cells.py [--seed 0] [--per-cell 20] [--planner lazy-ff] [--results FILE]

``--results`` reuses a ``gsr bench run gsr-bench-gen --agent planner`` results.json (same seed) instead of
planning again. The admissible lower bound per task (minimum over goal alternatives): 2 steps (pick +
place) per goal ``in`` relation false initially; +1 per closed openable container that must be entered;
+2 per other object lying on such a lid; +1 per open drawer above a drawer that must be entered. A plan
whose length equals the bound is optimal.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from collections import defaultdict
from pathlib import Path

from gsr.benchmarks.runner import RunConfig, run_tasks
from gsr.benchmarks.scoring import relations
from gsr.benchmarks.suites.gsr_bench_gen import generate_gsr_bench

from gsr.facts import node_affordances, state_from_graph
from gsr.pddl.model import Atom, Domain, Formula
from gsr.resources import load_builtin_domain
from gsr.semantics import holds
from gsr.state import State
from gsr.task_spec import TaskSpec


def lower_bound(domain: Domain, task: TaskSpec, goal: Formula, state: State) -> int:
    """An admissible lower bound on the plan length to ``goal`` (see the module docstring)."""
    g = task.initial
    nodes = {n.id: n for n in g.nodes}
    holder = {e.source: e.target for e in g.edges if e.relation in ("on", "in")}
    on_edges = {e.source for e in g.edges if e.relation == "on"}
    todo = [p for p in relations(goal) if not holds(domain, p, state)]
    moved = {p.args[0] for p in todo if isinstance(p, Atom)}
    enter = {p.args[1] for p in todo if isinstance(p, Atom)} | {holder[o] for o in moved if o in holder}
    closed = {
        c
        for c in enter
        if c in nodes and "openable" in node_affordances(nodes[c]) and "open" not in nodes[c].states
    }
    cost = 2 * len(todo) + len(closed)
    cost += 2 * sum(1 for o, h in holder.items() if h in closed and o not in moved and o in on_edges)
    above: set[str] = set()
    for c in enter:
        n = nodes.get(c)
        level = n.attributes.get("level") if n is not None else None
        if n is None or n.parent is None or level is None:
            continue
        for m in g.nodes:
            mlevel = m.attributes.get("level")
            if m.parent == n.parent and mlevel is not None and mlevel > level and "open" in m.states:
                above.add(m.id)
    return cost + len(above)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--per-cell", type=int, default=20)
    parser.add_argument("--planner", default="lazy-ff")
    parser.add_argument("--results", type=Path, help="reuse a planner results.json of gsr-bench-gen")
    args = parser.parse_args()
    domain = load_builtin_domain("tabletop")
    tasks = generate_gsr_bench(args.seed, args.per_cell)
    if args.results:
        lengths = {r["id"]: r["steps"] for r in json.loads(args.results.read_text())["tasks"] if r["success"]}
    else:
        results = run_tasks(tasks, RunConfig(agent="planner", agent_options={"planner": args.planner}))
        lengths = {r.id: r.steps for r in results if r.success}
    cells: dict[tuple[str, str], list[tuple[int, int]]] = defaultdict(list)
    for t in tasks:
        if t.id not in lengths:
            print(f"unsolved: {t.id}", file=sys.stderr)
            continue
        state = state_from_graph(t.initial, domain)
        bound = min(lower_bound(domain, t, f, state) for f in t.goal_formulas())
        cells[(t.category, t.level or "")].append((lengths[t.id], bound))
    print("| cell | tasks | mean plan length (best found) | mean lower bound | certified optimal |")
    print("|---|---|---|---|---|")
    for (cat, level), rows in cells.items():
        mean_len = statistics.fmean(a for a, _ in rows)
        mean_lb = statistics.fmean(b for _, b in rows)
        optimal = sum(a == b for a, b in rows)
        print(f"| {cat} / {level} | {len(rows)} | {mean_len:.2f} | {mean_lb:.2f} | {optimal}/{len(rows)} |")
    allrows = [r for rows in cells.values() for r in rows]
    print(f"\nall {len(allrows)} tasks: mean plan length {statistics.fmean(a for a, _ in allrows):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
