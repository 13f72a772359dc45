"""Profile GSR's landmark graph and its lama search on one IPC problem.

Prints the landmarks (single-fact and disjunctive), the orders by kind (greedy-necessary, natural,
reasonable, obedient-reasonable), the mutex groups they used, the CPU seconds of grounding, of the
landmark graph and of the search, and the search's outcome and expansions. CPU times are this
process's own (``time.process_time``); ``--timeout`` bounds the search's *wall* time.

Usage: python -m gsr.benchmarks.landmark_profile DOMAIN PROBLEM [--timeout 60] [--[no-]disjunctive]
       [--no-reasonable] [--graph] [--trace] [--fd] [--progression past-future|accept]
       [--lm-preferred on|off] [--boost-root on|off] [--tie-order 1,3,0,2] [--[no-]lifo] [--dovetail N]
       [--type-based]

The search switches are ``gsr.plan.search.LamaOptions``: GSR's defaults (planner ``lama``), or with
``--fd`` Fast Downward lama-first's rules (past/future progression, h_FF's preferred operators only,
no boost at the initial state, ties in list order); each switch given overrides the one of that base.
``--[no-]disjunctive`` and ``--[no-]lifo`` are ``LamaOptions.disjunctive`` / ``.lifo`` (the landmark
graph and the main search's h_add order).
"""

from __future__ import annotations

import argparse
import gc
import resource
import sys
import time
from dataclasses import replace
from pathlib import Path

from gsr.errors import GSRError
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.landmarks_progress import Progression
from gsr.plan.search import FD_LAMA_FIRST, LAMA_FIRST, LamaOptions, lazy_lama


def profile(
    domain: Path,
    problem: Path,
    timeout: float,
    disjunctive: bool,
    reasonable: bool,
    options: LamaOptions = LAMA_FIRST,
    trace: list | None = None,
    lifo: bool = False,
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
    relax.lifo = lifo
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
    parser.add_argument(
        "--disjunctive",
        action=argparse.BooleanOptionalAction,
        help="RHW's disjunctive landmarks too (default: the base rules')",
    )
    parser.add_argument("--no-reasonable", action="store_true", help="greedy-necessary orders only")
    parser.add_argument("--fd", action="store_true", help="Fast Downward lama-first's search rules")
    parser.add_argument("--progression", choices=("past-future", "accept"), help="landmark status rule")
    parser.add_argument("--lm-preferred", choices=("on", "off"), help="landmark preferred operators")
    parser.add_argument("--boost-root", choices=("on", "off"), help="the initial state's values boost")
    parser.add_argument(
        "--lm-preferred-disjunctive",
        choices=("on", "off"),
        help="the disjunctive landmarks' achievers are landmark-preferred too",
    )
    parser.add_argument("--tie-order", help="queue order on equal priorities, e.g. 1,3,0,2")
    parser.add_argument(
        "--lifo",
        action=argparse.BooleanOptionalAction,
        help="the main search's h_add buckets last in first out (Fast Downward's order; default: the base rules')",
    )
    parser.add_argument(
        "--dovetail",
        type=int,
        help="slices of the main search per slice of the other h_add order's search (0: off)",
    )
    parser.add_argument(
        "--type-based",
        action="store_true",
        help="a fifth, type-based queue keyed (h_FF, g) (Xie et al. 2014)",
    )
    parser.add_argument("--trace", action="store_true", help="print each new best h_FF / landmark value")
    parser.add_argument("--graph", action="store_true", help="print every landmark and its predecessors")
    args = parser.parse_args(argv)
    options = FD_LAMA_FIRST if args.fd else LAMA_FIRST
    if args.tie_order is not None:
        try:
            ties = tuple(int(x) for x in args.tie_order.split(","))
        except ValueError:
            ties = ()
        if sorted(ties) != [0, 1, 2, 3]:
            print(
                f"landmark_profile: --tie-order must order 0,1,2,3, not {args.tie_order!r}", file=sys.stderr
            )
            return 2
        options = replace(options, tie_order=ties)
    if args.progression is not None:
        options = replace(options, progression=args.progression)
    if args.lm_preferred is not None:
        options = replace(options, lm_preferred=args.lm_preferred == "on")
    if args.boost_root is not None:
        options = replace(options, boost_root=args.boost_root == "on")
    if args.lm_preferred_disjunctive is not None:
        options = replace(options, lm_preferred_disjunctive=args.lm_preferred_disjunctive == "on")
    if args.dovetail is not None:
        options = replace(options, dovetail=max(0, args.dovetail))
    if args.type_based:
        options = replace(options, type_based=True)
    if args.lifo is not None:
        options = replace(options, lifo=args.lifo)
    if args.disjunctive is not None:
        options = replace(options, disjunctive=args.disjunctive)
    trace: list | None = [] if args.trace else None
    try:
        out = profile(
            args.domain,
            args.problem,
            args.timeout,
            options.disjunctive,
            not args.no_reasonable,
            options,
            trace,
            options.lifo,
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
