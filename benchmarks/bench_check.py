"""Step-checker throughput on a 50-object tabletop scene graph (valid-only, mixed and invalid-only workloads).

Run: ``python benchmarks/bench_check.py [--objects 50] [--seconds 3] [--json] [--seed 0]``.
The scene (a table, a cabinet with three drawers, boxes, plates, bowls, mugs, blocks and cubes) is
turned into two states once (hand empty / holding a cube); every check is a full ``check_step``
call on a different ground step, cycling through a shuffled pool. Invalid steps get their whole
diagnosis (explanation and repair hints), so the mixed figure includes that cost.
"""

from __future__ import annotations

import argparse
import itertools
import json
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gsr.check import check_step
from gsr.facts import state_from_graph
from gsr.pddl.model import Atom
from gsr.resources import load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.state import State
from gsr.step import Step

COLORS = ("red", "blue", "green", "yellow", "white", "black")


def scene(n_objects: int, seed: int) -> SceneGraph:
    """A tabletop scene with ``n_objects`` nodes (furniture, drawers, containers, tableware, cubes)."""
    rng = random.Random(seed)
    nodes = [
        Node(id="table", category="table"),
        Node(id="short_cabinet", category="cabinet"),
        Node(
            id="short_cabinet/drawer_high", category="drawer", parent="short_cabinet", attributes={"level": 3}
        ),
        Node(
            id="short_cabinet/drawer_middle",
            category="drawer",
            parent="short_cabinet",
            attributes={"level": 2},
        ),
        Node(
            id="short_cabinet/drawer_low",
            category="drawer",
            parent="short_cabinet",
            attributes={"level": 1},
            states=("open",),
        ),
        Node(id="stove", category="stove"),
    ]
    edges = [
        Edge(source="short_cabinet", relation="on", target="table"),
        Edge(source="stove", relation="on", target="table"),
    ]
    containers = ["short_cabinet/drawer_high", "short_cabinet/drawer_middle", "short_cabinet/drawer_low"]
    supporters = ["table"]
    kinds = itertools.cycle(
        ["box", "lidded_box", "plate", "bowl", "mug", "basket", "block", "cube", "cube", "cube"]
    )
    counters: dict[str, int] = {}
    while len(nodes) < n_objects:
        kind = next(kinds)
        color = COLORS[counters.get(kind, 0) % len(COLORS)]
        counters[kind] = counters.get(kind, 0) + 1
        name = f"{color}_{kind}{counters[kind]}"
        states = ("closed",) if kind == "lidded_box" and counters[kind] % 2 else ()
        nodes.append(Node(id=name, category=kind, attributes={"color": color}, states=states))
        if kind == "cube" and containers and rng.random() < 0.4:
            edges.append(Edge(source=name, relation="in", target=rng.choice(containers)))
        elif kind in ("cube", "block", "mug") and len(supporters) > 1 and rng.random() < 0.3:
            edges.append(Edge(source=name, relation="on", target=rng.choice(supporters[1:])))
        else:
            edges.append(Edge(source=name, relation="on", target="table"))
        if kind in ("box", "lidded_box", "basket", "bowl"):
            containers.append(name)
        if kind in ("plate", "bowl", "box"):
            supporters.append(name)
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges))


def step_pools(domain, states: list[State], seed: int) -> tuple[list, list]:
    """(valid, invalid) lists of (state, step), from every ground instance over things (push sampled)."""
    rng = random.Random(seed)
    valid, invalid = [], []
    for state in states:
        things = sorted(o for o, t in state.objects.items() if domain.is_subtype(t, "thing"))
        for name, action in domain.actions.items():
            combos = itertools.product(things, repeat=len(action.params))
            if len(action.params) > 2:
                combos = (tuple(rng.choice(things) for _ in action.params) for _ in range(3000))
            for args in combos:
                step = Step(name, args)
                (valid if check_step(domain, state, step).ok else invalid).append((state, step))
    # Malformed steps an LLM produces: typos, unknown objects, wrong arity, wrong claimed effects.
    state = states[0]
    things = sorted(o for o, t in state.objects.items() if domain.is_subtype(t, "thing"))
    for i in range(400):
        obj = rng.choice(things)
        kind = i % 4
        if kind == 0:
            step = Step("pick_up", (obj, "table"))
        elif kind == 1:
            step = Step("pick", (obj + "x", "table"))
        elif kind == 2:
            step = Step("open", (obj, "table"))
        else:
            ok = [s for st, s in valid[:200] if st is state and s.action == "pick"]
            base = rng.choice(ok)
            step = Step(base.action, base.args, add=(Atom("holding", (base.args[0],)),), delete=())
        invalid.append((state, step))
    rng.shuffle(valid)
    rng.shuffle(invalid)
    return valid, invalid


def cold_rate(workload: list, seconds: float) -> float:
    """Invalid checks/s with the per-state explanation memo dropped before every check (worst case)."""
    domain = workload[0][0]
    n = 0
    start = time.perf_counter()
    deadline = start + seconds
    while time.perf_counter() < deadline:
        for _, state, step in workload[:500]:
            state.__dict__.pop("_gsr_memo", None)
            check_step(domain, state, step)
        n += min(len(workload), 500)
    return n / (time.perf_counter() - start)


def successor_rate(workload: list, seconds: float) -> float:
    """Valid checks/s including building each next state (``Diagnosis.next_state``)."""
    domain = workload[0][0]
    n = 0
    start = time.perf_counter()
    deadline = start + seconds
    while time.perf_counter() < deadline:
        for _, state, step in workload:
            assert check_step(domain, state, step).next_state is not None
        n += len(workload)
    return n / (time.perf_counter() - start)


def rate(workload: list, seconds: float) -> tuple[float, int]:
    """Checks per second over ``workload`` (cycled) for about ``seconds``."""
    domain = workload[0][0]
    n = 0
    start = time.perf_counter()
    deadline = start + seconds
    while True:
        for _, state, step in workload:
            check_step(domain, state, step)
        n += len(workload)
        now = time.perf_counter()
        if now >= deadline:
            return n / (now - start), n


def main(argv: list[str] | None = None) -> int:
    """Build the scene, the step pools and print checks/s per workload."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--invalid-share", type=float, default=0.5, help="share of invalid steps in 'mixed'")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)

    domain = load_builtin_domain("tabletop")
    graph = scene(args.objects, args.seed)
    empty = state_from_graph(graph, domain)
    cube = next(n.id for n in graph.nodes if n.category == "cube")
    held_atoms = {a for a in empty.atoms if not (a.predicate in ("on", "in") and a.args[0] == cube)}
    holding = State(frozenset(held_atoms | {Atom("holding", (cube,))}), empty.objects)
    valid, invalid = step_pools(domain, [empty, holding], args.seed)
    n_mixed = 4000
    n_bad = int(n_mixed * args.invalid_share)
    mixed = [valid[i % len(valid)] for i in range(n_mixed - n_bad)] + invalid[:n_bad]
    random.Random(args.seed).shuffle(mixed)
    results = {
        "objects": len(graph.nodes),
        "atoms": len(empty.atoms),
        "valid_pool": len(valid),
        "invalid_pool": len(invalid),
        "invalid_share_mixed": args.invalid_share,
    }
    for label, pool in (("valid_only", valid), ("mixed", mixed), ("invalid_only", invalid)):
        workload = [(domain, s, st) for s, st in pool]
        per_s, n = rate(workload, args.seconds)
        results[f"{label}_checks_per_s"] = round(per_s)
        results[f"{label}_us_per_check"] = round(1e6 / per_s, 2)
        results[f"{label}_checks"] = n
    cold = cold_rate([(domain, s, st) for s, st in invalid], args.seconds)
    results["invalid_cold_memo_checks_per_s"] = round(cold)
    results["invalid_cold_memo_us_per_check"] = round(1e6 / cold, 2)
    succ = successor_rate([(domain, s, st) for s, st in valid], args.seconds)
    results["valid_with_next_state_checks_per_s"] = round(succ)
    results["valid_with_next_state_us_per_check"] = round(1e6 / succ, 2)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        print(
            f"scene: {results['objects']} objects, {results['atoms']} atoms; "
            f"pools: {len(valid)} valid, {len(invalid)} invalid steps"
        )
        for label in ("valid_only", "mixed", "invalid_only", "invalid_cold_memo", "valid_with_next_state"):
            print(
                f"{label:>21}: {results[f'{label}_checks_per_s']:>9,} checks/s "
                f"({results[f'{label}_us_per_check']} µs/check)"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
