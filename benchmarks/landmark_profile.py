"""Profile GSR's landmark graph and its lama search on one IPC problem.

Prints the landmarks (single-fact and disjunctive), the orders by kind (greedy-necessary, natural,
reasonable, obedient-reasonable), the mutex groups they used, the CPU seconds of grounding, of the
landmark graph and of the search, and the search's outcome and expansions. CPU times are this
process's own (``time.process_time``); ``--timeout`` bounds the search's *wall* time.

Usage: python -m gsr.benchmarks.landmark_profile DOMAIN PROBLEM [--timeout 60] [--disjunctive]
       [--no-reasonable] [--graph] [--progression past-future|accept] [--lm-preferred]
       [--boost-root] [--tie-order 0,1,2,3] [--old]

The search switches are ``gsr.plan.search.LamaOptions`` (defaults: lama-first's); ``--old`` is the
search before issue 18's fifth pass (accept progression, landmark preferred operators, a boost at
the initial state, ties 1,3,0,2).
"""

from __future__ import annotations

import argparse
import gc
import resource
import sys
import time
from pathlib import Path

from gsr.errors import GSRError
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.landmarks_progress import Progression
from gsr.plan.search import LAMA_FIRST, LamaOptions, lazy_lama

OLD = LamaOptions(progression="accept", lm_preferred=True, boost_root=True, tie_order=(1, 3, 0, 2))


def profile(
    domain: Path,
    problem: Path,
    timeout: float,
    disjunctive: bool,
    reasonable: bool,
    options: LamaOptions = LAMA_FIRST,
    trace: list | None = None,
) -> dict:
    """Ground, build the landmark graph, search; the figures as a dict (``lm`` the graph)."""
    c0 = time.process_time()
    dom = load_domain(domain)
    prob = load_problem(problem, dom)
    gc.disable()
    try:
        task = ground_task(dom, prob, time.perf_counter() + 10 * timeout)
    finally:
        gc.enable()
    c1 = time.process_time()
    relax = Relaxation(task, unit=True)
    c2 = time.process_time()
    lm = Landmarks(task, disjunctive=disjunctive, reasonable=reasonable)
    c3 = time.process_time()
    result = lazy_lama(task, relax, lm, time.perf_counter() + timeout, options, trace)
    c4 = time.process_time()
    orders = lm.orders
    return {
        "operators": len(task.ops),
        "atoms": len(task.atoms),
        "landmarks": len(lm.facts),
        "disjunctive": sum(len(f) > 1 for f in lm.facts),
        "greedy_necessary": sum(p.bit_count() for p in lm.gn_parents),
        "natural": len(orders.natural) if orders else 0,
        "reasonable": len(orders.reasonable) if orders else 0,
        "obedient": len(orders.obedient) if orders else 0,
        "mutex_groups": len(orders.mutexes.groups) if orders else 0,
        "initial_h": (
            Progression(lm).value(Progression(lm).initial(task.init))
            if options.progression == "past-future"
            else lm.value(lm.accept(0, task.init), task.init)[0]
        ),
        "ground_cpu": c1 - c0,
        "relax_cpu": c2 - c1,
        "landmark_cpu": c3 - c2,
        "search_cpu": c4 - c3,
        "status": result.status,
        "plan_length": len(result.ops),
        "expanded": result.expanded,
        "evaluated": result.evaluated,
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024,
        "lm": lm,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("domain", type=Path)
    parser.add_argument("problem", type=Path)
    parser.add_argument("--timeout", type=float, default=60.0, help="wall seconds of search")
    parser.add_argument("--disjunctive", action="store_true", help="RHW's disjunctive landmarks too")
    parser.add_argument("--no-reasonable", action="store_true", help="greedy-necessary orders only")
    parser.add_argument("--progression", choices=("past-future", "accept"), default=LAMA_FIRST.progression)
    parser.add_argument("--lm-preferred", action="store_true", help="landmark preferred operators too")
    parser.add_argument("--boost-root", action="store_true", help="the initial state's values boost")
    parser.add_argument("--tie-order", default="0,1,2,3", help="queue order on equal priorities")
    parser.add_argument("--old", action="store_true", help="the search before the fifth pass")
    parser.add_argument("--trace", action="store_true", help="print each new best h_FF / landmark value")
    parser.add_argument("--graph", action="store_true", help="print every landmark and its predecessors")
    args = parser.parse_args(argv)
    try:
        ties = tuple(int(x) for x in args.tie_order.split(","))
    except ValueError:
        ties = ()
    if sorted(ties) != [0, 1, 2, 3]:
        print(f"landmark_profile: --tie-order must order 0,1,2,3, not {args.tie_order!r}", file=sys.stderr)
        return 2
    options = OLD if args.old else LamaOptions(args.progression, args.lm_preferred, args.boost_root, ties)
    trace: list | None = [] if args.trace else None
    try:
        out = profile(
            args.domain, args.problem, args.timeout, args.disjunctive, not args.no_reasonable, options, trace
        )
    except (GSRError, OSError) as err:
        print(f"landmark_profile: {err}", file=sys.stderr)
        return 2
    lm = out.pop("lm")
    for expanded, name, value in trace or ():
        print(f"new best {name} {value} after {expanded} expansions")
    if args.graph:
        for k in range(len(lm.facts)):
            before = [lm.describe(p) for p in range(len(lm.facts)) if lm.parents[k] >> p & 1]
            print(f"{lm.describe(k)} <- {'; '.join(before)}")
    print(" ".join(f"{k}={v:.2f}" if isinstance(v, float) else f"{k}={v}" for k, v in out.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
