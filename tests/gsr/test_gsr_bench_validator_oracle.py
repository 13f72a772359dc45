"""Oracle test: GSR's GSR-Bench rules (gsr.gsr_bench_rules) against an independent re-implementation of the
benchmark's validator, on thousands of random commands along random walks.

The oracle below is written from the validator's code (KLMmotion/GSR-bench,
``langgraph_agent/tools/action_validation_execution_tool.py``: ``_validate_action_command``,
``_can_move_object``, ``_can_access_target``, ``_validate_cube_source_accessibility``,
``_can_place_cube_in_box``, ``_check_drawer_constraints``, ``_check_action_already_completed``,
``_validate_open_close_action``), working as it does on the raw ``nodes``/``edges`` strings, with
substring tests on names and edges. It labels each rejection with the rule of the check that
fired. GSR's checker works on a parsed SceneGraph; both must give the same verdict and the same rule
for every command, and the same edges after every accepted move.

The walks start from the 90 published dev configs (shared data; skipped when absent) and from the
project's own generated GSR-Bench configs (always available). Each step samples commands of every kind
(valid and invalid moves, opens and closes, unknown names, malformed text), then follows a random
accepted command, so deep states (emptied, refilled, re-covered containers, opened drawers) are reached.
A second check: every move the tabletop domain allows (pick + place) is one the oracle accepts.
"""

from __future__ import annotations

import random
import re
from collections import Counter

import pytest
import yaml

from gsr.check import check_step
from gsr.facts import state_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench, gsr_bench_message
from gsr.gsr_bench_rules import check_command, transition
from gsr.resources import load_builtin_domain
from gsr.step import Step

# ------------------------------------------------------------ the oracle (validator semantics on strings)


def _strip(name: str) -> str:
    return name.replace("(open)", "").replace("(closed)", "")


def o_parse(command: str):
    command = command.strip().lower()
    for pat in (
        r"(open|close)\s+([a-zA-Z_][a-zA-Z0-9_/]*)",
        r"action\s+type\s+\d+\s*:\s*(open|close)\s+([a-zA-Z_][a-zA-Z0-9_/]*)",
    ):
        m = re.match(pat, command)
        if m:
            return (m.group(1), m.group(2), None, None)
    name = r"([a-zA-Z_][a-zA-Z0-9_/]*)"
    rel = r"(in|into|to|on|upon)"
    for pat in (
        rf"move\s+{name}\s+{rel}\s+([a-zA-Z_][a-zA-Z0-9_/]*|table)",
        rf"action\s+type\s+\d+\s*:\s*move\s+{name}\s+{rel}\s+([a-zA-Z_][a-zA-Z0-9_/]*|table)",
        rf"[Pp]ut\s+{name}\s+{rel}\s+([a-zA-Z_][a-zA-Z0-9_/]*|table)",
        rf"action\s+type\s+\d+\s*:\s*[Pp]ut\s+{name}\s+{rel}\s+([a-zA-Z_][a-zA-Z0-9_/]*|table)",
    ):
        m = re.match(pat, command)
        if m:
            r = m.group(2)
            r = "in" if r == "into" else ("on" if r in ("to", "upon") else r)
            return ("move", m.group(1), r, m.group(3))
    return None


def o_state(obj: str, nodes: list[str], edges: list[str]):
    for node in nodes:
        if str(node).startswith(f"{obj}("):
            if "(open)" in node:
                return "open"
            if "(closed)" in node:
                return "closed"
    for edge in edges:
        if obj in edge:
            if f"{obj}(open)" in edge:
                return "open"
            if f"{obj}(closed)" in edge:
                return "closed"
    return None


def o_is_cube(n: str) -> bool:
    return n.endswith("_cube") or "cube" in n.lower()


def o_is_mug(n: str) -> bool:
    return n.endswith("_mug") or "mug" in n.lower()


def o_is_container(n: str) -> bool:
    low = n.lower()
    return "drawer" in low or "lid_box" in low or low.endswith("_box")


def o_drawer(drawer: str, nodes, edges):
    """(ok, rule) of _check_drawer_constraints; rule_closed is the caller's 'not open' label."""
    if o_state(drawer, nodes, edges) != "open":
        return False, "closed"
    if drawer == "short_cabinet/drawer_low":
        if o_state("short_cabinet/drawer_middle", nodes, edges) == "open":
            return False, "drawer_order"
        if o_state("short_cabinet/drawer_high", nodes, edges) == "open":
            return False, "drawer_order"
    elif drawer == "short_cabinet/drawer_middle":  # noqa: SIM102 (the validator's structure)
        if o_state("short_cabinet/drawer_high", nodes, edges) == "open":
            return False, "drawer_order"
    return True, None


def oracle(command: str, nodes: list[str], edges: list[str]) -> tuple[bool, str | None]:
    """(valid, rule) as GSR-Bench's validator decides (rule: which check rejected it)."""
    parsed = o_parse(command)
    if not parsed:
        return False, "unparsable_command"
    verb, src, rel, tgt = parsed
    if verb in ("open", "close"):
        found, state = False, None
        for node in nodes:
            if node == src:
                found = True
                break
            if node.startswith(f"{src}("):
                found = True
                state = "open" if "(open)" in node else ("closed" if "(closed)" in node else None)
                break
        if not found:
            for edge in edges:
                if src in edge:
                    found = True
                    state = (
                        "open" if f"{src}(open)" in edge else ("closed" if f"{src}(closed)" in edge else None)
                    )
                    break
        if not found:
            return False, "unknown_object"
        if state is None:
            return False, "not_openable"
        if (verb == "open" and state == "open") or (verb == "close" and state == "closed"):
            return False, "already_done"
        return True, None
    all_objects = set()
    for edge in edges:
        if "(on)" in edge or "(in)" in edge:
            parts = edge.split("(on)") if "(on)" in edge else edge.split("(in)")
            if len(parts) == 2:
                for p in parts:
                    if _strip(p.strip()) != "table":
                        all_objects.add(_strip(p.strip()))
    for node in nodes:
        if node != 0 and _strip(node) and _strip(node) != "table":
            all_objects.add(_strip(node))
    if src not in all_objects:
        return False, "unknown_object"
    if tgt != "table" and tgt not in all_objects:
        return False, "unknown_object"
    if o_is_cube(src):  # _validate_cube_source_accessibility
        loc, inside = None, False
        for edge in edges:
            if f"{src}(in)" in edge:
                parts = edge.split("(in)")
                if len(parts) == 2 and parts[0].strip() == src:
                    loc, inside = parts[1].strip(), True
                    break
            elif f"{src}(on)" in edge:
                parts = edge.split("(on)")
                if len(parts) == 2 and parts[0].strip() == src:
                    loc = parts[1].strip()
                    inside = loc != "table"
                    break
        if not loc:
            return False, "source_unlocated"
        if loc != "table" and inside and any("(on)" in e and e.endswith(f"(on){loc}") for e in edges):
            return False, "source_container_blocked"
    # _can_move_object
    for edge in edges:
        if "(on)" in edge:
            parts = edge.split("(on)")
            if len(parts) == 2 and parts[1].strip() == src:
                return False, "source_blocked"
    holder = None
    for edge in edges:
        if "(in)" in edge:
            parts = edge.split("(in)")
            if len(parts) == 2 and parts[0].strip() == src:
                holder = parts[1].strip()
                break
    if holder:
        if o_state(holder, nodes, edges) == "closed":
            return False, "source_container_closed"
        if "drawer" in holder:
            ok, why = o_drawer(holder, nodes, edges)
            if not ok:
                return False, "source_container_closed" if why == "closed" else why
        for edge in edges:
            if "(on)" in edge:
                parts = edge.split("(on)")
                if len(parts) == 2 and parts[1].strip() == holder:
                    return False, "source_container_blocked"
    if tgt != "table":
        if o_is_container(src) and o_is_container(tgt):
            return False, "container_in_container"
        if o_is_cube(tgt) or o_is_mug(tgt):
            return False, "not_a_support"
        for edge in edges:  # _can_access_target
            if "(on)" in edge:
                parts = edge.split("(on)")
                if len(parts) == 2 and parts[1].strip() == tgt:
                    return False, "target_blocked"
        if "lid_box" in tgt or "drawer" in tgt:
            if o_state(tgt, nodes, edges) == "closed":
                return False, "target_closed"
            if "drawer" in tgt:
                ok, why = o_drawer(tgt, nodes, edges)
                if not ok:
                    return False, "target_closed" if why == "closed" else why
        if o_is_cube(src):  # _can_place_cube_in_box (its blocking checks repeat earlier ones)
            n = 0
            for edge in edges:
                if "(in)" in edge and edge.endswith(f"(in){tgt}"):
                    parts = edge.split("(in)")
                    if len(parts) == 2 and o_is_cube(parts[0].strip()):
                        n += 1
            if n >= 10:
                return False, "cube_capacity"
    else:
        status = "T"
        for edge in edges:
            if "=" in edge and edge.startswith("0="):
                status = edge.split("=")[1]
        if status == "F":
            return False, "table_full"
    if f"{src}({rel}){tgt}" in edges:
        return False, "already_done"
    if tgt == "table" and f"{src}(on)table" in edges:
        return False, "already_done"
    return True, None


def o_apply(command: str, nodes: list[str], edges: list[str]) -> tuple[list[str], list[str]]:
    """The oracle's transition: the command's relation replaces the object's on/in edge; open/close flip."""
    verb, src, rel, tgt = o_parse(command)
    if verb in ("open", "close"):
        new = "open" if verb == "open" else "closed"
        return [f"{src}({new})" if _strip(n) == src else n for n in nodes], list(edges)
    kept = [e for e in edges if not (e.startswith(f"{src}(on)") or e.startswith(f"{src}(in)"))]
    return list(nodes), [*kept, f"{src}({'on' if tgt == 'table' else rel}){tgt}"]


# ------------------------------------------------------------ random commands and walks


def _commands(rng: random.Random, nodes: list[str], k: int) -> list[str]:
    names = [_strip(n) for n in nodes if _strip(n) != "table"]
    stated = [_strip(n) for n in nodes if n.endswith(")")]
    out = []
    for _ in range(k):
        r = rng.random()
        if r < 0.62:
            verb = rng.choice(["move", "move", "move", "put", "action type 1: move"])
            rel = rng.choice(["in", "in", "on", "into", "to", "upon"])
            tgt = "table" if rng.random() < 0.2 else rng.choice(names)
            out.append(f"{verb} {rng.choice(names)} {rel} {tgt}")
        elif r < 0.86 and stated:
            out.append(f"{rng.choice(['open', 'close'])} {rng.choice(stated)}")
        elif r < 0.9:
            out.append(f"{rng.choice(['open', 'close'])} {rng.choice([*names, 'table'])}")
        elif r < 0.95:
            out.append(f"move {rng.choice(['ghost_cube9', 'table', 'blue'])} in {rng.choice(names)}")
        else:
            out.append(
                rng.choice(
                    [
                        "",
                        "move",
                        "pick red_cube1",
                        "move red_cube1 beside table",
                        "MOVE " + rng.choice(names) + " ON table",
                    ]
                )
            )
    return out


def _walk_compare(
    message: dict, rng: random.Random, steps: int, per_state: int, stats: Counter, domain
) -> None:
    nodes, edges = list(message["nodes"]), list(message["edges"])
    graph = graph_from_gsr_bench(message)
    for _ in range(steps):
        candidates = _commands(rng, nodes, per_state)
        accepted = []
        state = state_from_graph(graph, domain)
        for command in candidates:
            want = oracle(command, nodes, edges)
            got = check_command(graph, command)
            stats["steps"] += 1
            stats["valid" if want[0] else "invalid"] += 1
            stats[want[1] or "ok"] += 1
            assert (got.ok, got.rule.value if got.rule else None) == want, (command, nodes, edges, got)
            if want[0]:
                accepted.append(command)
            _domain_soundness(domain, state, graph, command, want, stats)
        moves = [c for c in accepted if o_parse(c)[0] != "move" or o_parse(c)[1] != o_parse(c)[3]]
        if not moves:
            # force progress: try commands until one is accepted
            for command in _commands(rng, nodes, 60):
                p = o_parse(command)
                if oracle(command, nodes, edges)[0] and (p[0] != "move" or p[1] != p[3]):
                    moves = [command]
                    break
        if not moves:
            return
        command = rng.choice(moves)
        nodes, edges = o_apply(command, nodes, edges)
        from gsr.gsr_bench_rules import parse_command

        graph = transition(graph, parse_command(command))
        ours = gsr_bench_message(graph)
        assert sorted(ours["edges"]) == sorted(edges), command
        assert sorted(ours["nodes"]) == sorted(nodes), command
        stats["transitions"] += 1


def _domain_soundness(domain, state, graph, command: str, want, stats: Counter) -> None:
    """A move the tabletop domain allows (pick + place) must be one the validator accepts."""
    p = o_parse(command)
    if p is None or p[0] != "move":
        return
    _, src, rel, tgt = p
    support = next((e.target for e in graph.edges if e.source == src and e.relation in ("on", "in")), None)
    if support is None or src not in state.objects or tgt not in state.objects:
        return
    pick = check_step(domain, state, Step("pick", (src, support)))
    if not pick.ok:
        return
    place = check_step(domain, pick.next_state, Step("place_in" if rel == "in" else "place_on", (src, tgt)))
    if not place.ok:
        return
    stats["domain_allowed"] += 1
    if not want[0]:
        # The domain moves through the hand, so it does not see where the object was before the pick:
        # that a move changes nothing, or that the target is covered by the moving object itself.
        near = sorted(e.key() for e in graph.edges if {e.source, e.target} & {src, tgt})
        covering = [e.source for e in graph.edges if e.relation == "on" and e.target == tgt]
        own = want[1] == "already_done" or (want[1] == "target_blocked" and covering == [src])
        assert own, (command, want, near)
        stats["domain_own_place"] += 1


def _run(messages: list[dict], seed: int, steps: int, per_state: int) -> Counter:
    domain = load_builtin_domain("tabletop")
    rng = random.Random(seed)
    stats: Counter = Counter()
    for message in messages:
        _walk_compare(message, rng, steps, per_state, stats, domain)
    return stats


def test_oracle_on_published_dev_configs(shared_data) -> None:
    path = shared_data / "gsr_bench" / "saved_configs_dev.yaml"
    if not path.is_file():
        pytest.skip(f"GSR-Bench dev configs absent at {path}")
    configs = yaml.safe_load(path.read_text(encoding="utf-8"))["configs"]
    assert len(configs) == 90
    stats = _run([c["scene_graph"] for c in configs], seed=17, steps=14, per_state=5)
    assert stats["steps"] >= 5000
    # both kinds of verdict, and most rules, were exercised
    assert stats["valid"] >= 1000 and stats["invalid"] >= 1000
    for rule in (
        "source_blocked",
        "source_container_blocked",
        "target_blocked",
        "container_in_container",
        "not_a_support",
        "target_closed",
        "source_container_closed",
        "drawer_order",
        "already_done",
        "not_openable",
        "unknown_object",
        "unparsable_command",
    ):
        assert stats[rule] > 0, (rule, stats)
    assert stats["domain_allowed"] > 300


def test_oracle_on_generated_configs(generated_gsr_bench_configs) -> None:
    messages = [c["scene_graph"] for c in generated_gsr_bench_configs]
    stats = _run(messages, seed=3, steps=24, per_state=6)
    assert stats["steps"] >= 3000
    assert stats["valid"] >= 500 and stats["invalid"] >= 500
    for rule in (
        "source_blocked",
        "target_blocked",
        "container_in_container",
        "not_a_support",
        "already_done",
    ):
        assert stats[rule] > 0, (rule, stats)


def test_edge_rules_the_walks_rarely_reach() -> None:
    """Cube capacity, a cube stuck on a box, the table-full status and an unlocated cube, one scene each."""
    cubes = [f"red_cube{i}" for i in range(1, 12)]
    message = {
        "nodes": ["table", "red_box", "blue_box", *cubes, "blue_cube1", "blue_cube2"],
        "edges": [
            *(f"{c}(in)red_box" for c in cubes[:10]),
            f"{cubes[10]}(on)table",
            "blue_box(on)table",
            "red_box(on)table",
            "blue_cube1(on)blue_box",
        ],
    }
    graph = graph_from_gsr_bench(message)
    for command, rule in [
        (f"move {cubes[10]} in red_box", "cube_capacity"),
        ("move blue_cube1 on table", "source_container_blocked"),  # a cube on a box is stuck
        ("move blue_cube2 on table", "source_unlocated"),
        ("move blue_cube2 in blue_box", "source_unlocated"),
    ]:
        assert oracle(command, message["nodes"], message["edges"]) == (False, rule)
        verdict = check_command(graph, command)
        assert (verdict.ok, verdict.rule.value) == (False, rule), command
    full = {"nodes": message["nodes"], "edges": [*message["edges"], "0=F"]}
    assert oracle("move red_cube1 on table", full["nodes"], full["edges"]) == (False, "table_full")
    assert check_command(graph_from_gsr_bench(full), "move red_cube1 on table").rule.value == "table_full"
    assert gsr_bench_message(graph_from_gsr_bench(full))["edges"][-1] == "0=F"
    # the domain sees the full table too: nothing can be placed on it
    domain = load_builtin_domain("tabletop")
    state = state_from_graph(graph_from_gsr_bench(full), domain)
    held = check_step(domain, state, Step("pick", ("red_cube1", "red_box")))
    assert held.ok
    assert not check_step(domain, held.next_state, Step("place_on", ("red_cube1", "table"))).ok
