"""The GSR-Bench scene-graph message format: ``{"nodes": [...], "edges": [...]}`` of strings.

Nodes are names with an optional state suffix (``table``, ``short_cabinet/drawer_low(closed)``);
a ``parent/part`` name is an articulated part of ``parent``. Edges are ``source(relation)target``
(``red_cube1(on)table``). Categories and colours come from the category registry; drawer levels
from ``drawer_low`` / ``drawer_middle`` / ``drawer_high``.

A ``0=<status>`` edge is the table's status in the benchmark's older text format (node ``0`` is the
table; ``0=F``: the table is full, ``0=T``: it is not). Its validator rejects moves onto a full table;
``0=F`` becomes the table node's state ``full`` (the 3D desk's messages carry no status edge). Graphs
read here carry ``metadata["rules"] = "gsr-bench"``: the scene obeys GSR-Bench's action rules
(:mod:`gsr.gsr_bench_rules`), which the tabletop domain's facts take into account.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Any

from pydantic import ValidationError

from gsr.categories import category_of
from gsr.errors import GSRError
from gsr.scene_graph import RELATIONS, Edge, Node, SceneGraph, format_validation_error
from gsr.step import Step

_NODE = re.compile(r"^\s*([^()\s]+)\s*(?:\(\s*([A-Za-z_]+)\s*\))?\s*$")
_STATUS = re.compile(r"^\s*0\s*=\s*([A-Za-z]+)\s*$")
_EDGE = re.compile(r"^\s*([^()\s]+?)\s*\(\s*([A-Za-z_]+)\s*\)\s*([^()\s]+?)\s*(?:\(\s*[A-Za-z_]+\s*\))?\s*$")
#: States written as a suffix, in order of preference when a node has several.
SUFFIX_STATES: tuple[str, ...] = ("open", "closed", "on", "off", "held")


def _check_parens(text: str, what: str) -> None:
    depth = 0
    for ch in text:
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth < 0 or depth > 1:
            raise GSRError(f"GSR-Bench {what} {text!r}: unbalanced parentheses")
    if depth:
        raise GSRError(f"GSR-Bench {what} {text!r}: unbalanced parentheses")


def parse_node(text: str) -> tuple[str, str | None]:
    """``short_cabinet/drawer_low(closed)`` -> ``("short_cabinet/drawer_low", "closed")``."""
    if not isinstance(text, str):
        raise GSRError(f"GSR-Bench node {text!r}: expected a string")
    _check_parens(text, "node")
    m = _NODE.match(text)
    if not m:
        raise GSRError(f"GSR-Bench node {text!r}: expected NAME or NAME(state)")
    return m.group(1).lower(), (m.group(2).lower() if m.group(2) else None)


def parse_edge(text: str) -> tuple[str, str, str]:
    """``red_cube1(on)table`` -> ``("red_cube1", "on", "table")``; a state suffix on the target is ignored."""
    if not isinstance(text, str):
        raise GSRError(f"GSR-Bench edge {text!r}: expected a string")
    if text.count("(") != text.count(")"):
        raise GSRError(f"GSR-Bench edge {text!r}: unbalanced parentheses")
    m = _EDGE.match(text)
    if not m:
        raise GSRError(f"GSR-Bench edge {text!r}: expected SOURCE(relation)TARGET")
    source, relation, target = m.group(1).lower(), m.group(2).lower(), m.group(3).lower()
    if relation not in RELATIONS:
        raise GSRError(
            f"GSR-Bench edge {text!r}: unknown relation {relation!r} (expected one of {', '.join(RELATIONS)})"
        )
    return source, relation, target


def node_from_name(node_id: str, state: str | None = None, parent: str | None = None) -> Node:
    """A node for a GSR-Bench name: category and attributes from the registry."""
    category, attrs = category_of(node_id)
    if category != "drawer":
        attrs.pop("level", None)
    states = (state,) if state else ()
    try:
        return Node(id=node_id, category=category, attributes=attrs, states=states, parent=parent)
    except ValidationError as exc:
        raise GSRError(f"GSR-Bench node {node_id!r}: {format_validation_error(exc)}") from None


def graph_from_gsr_bench(message: Mapping[str, Any]) -> SceneGraph:
    """A SceneGraph from a GSR-Bench ``{"nodes": [...], "edges": [...]}`` message (node order kept)."""
    if not isinstance(message, Mapping):
        raise GSRError(
            f"GSR-Bench scene graph: expected a mapping with nodes and edges, got {type(message).__name__}"
        )
    raw_nodes = message.get("nodes")
    raw_edges = message.get("edges") or []
    if not isinstance(raw_nodes, list | tuple) or not isinstance(raw_edges, list | tuple):
        raise GSRError("GSR-Bench scene graph: 'nodes' and 'edges' must be lists of strings")
    parsed = [(text, *parse_node(text)) for text in raw_nodes]
    ids: set[str] = set()
    nodes: list[Node] = []
    for text, node_id, _ in parsed:
        if node_id in ids:
            raise GSRError(f"GSR-Bench node {text!r}: duplicate node {node_id!r}")
        ids.add(node_id)
    for text, node_id, state in parsed:
        parent = node_id.rsplit("/", 1)[0] if "/" in node_id else None
        if parent is not None and parent not in ids:
            raise GSRError(f"GSR-Bench node {text!r}: parent {parent!r} is not a node")
        nodes.append(node_from_name(node_id, state, parent))
    edges: list[Edge] = []
    seen: set[tuple[str, str, str]] = set()
    table_full = False
    for text in raw_edges:
        status = _STATUS.match(text) if isinstance(text, str) else None
        if status is not None:
            table_full = status.group(1).upper() == "F"
            continue
        source, relation, target = parse_edge(text)
        for end in (source, target):
            if end not in ids:
                raise GSRError(f"GSR-Bench edge {text!r}: {end!r} is not a node (dangling edge)")
        if source == target:
            raise GSRError(f"GSR-Bench edge {text!r}: an object cannot relate to itself")
        if (source, relation, target) in seen:
            continue  # repeated strings carry no information
        seen.add((source, relation, target))
        edges.append(Edge(source=source, relation=relation, target=target))
    if table_full:
        if "table" not in ids:
            raise GSRError("GSR-Bench scene graph: a 0=F table status but no 'table' node")
        nodes = [
            n.model_copy(update={"states": tuple(sorted({*n.states, "full"}))}) if n.id == "table" else n
            for n in nodes
        ]
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges), metadata={"rules": "gsr-bench"})


def node_text(node: Node) -> str:
    """A node's GSR-Bench string: its id with a state suffix (``(open)``, ``(closed)``, ...)."""
    for s in SUFFIX_STATES:
        if s in node.states:
            return f"{node.id}({s})"
    return node.id


def gsr_bench_message(graph: SceneGraph) -> dict[str, list[str]]:
    """The GSR-Bench ``{"nodes": [...], "edges": [...]}`` message of a graph (node and edge order kept)."""
    edges = [f"{e.source}({e.relation}){e.target}" for e in graph.edges]
    if any(n.id == "table" and "full" in n.states for n in graph.nodes):
        edges.append("0=F")
    return {"nodes": [node_text(n) for n in graph.nodes], "edges": edges}


_MOVES = {"place_in": "in", "place_on": "on", "stack": "on"}


def gsr_bench_commands(steps: Iterable[Step]) -> list[str]:
    """A tabletop plan in GSR-Bench's action language: ``move X in|on Y``, ``open X``, ``close X``.

    A ``pick`` followed by the placement of the same object becomes one ``move``; any other action
    (turn on, press, push) or a pick that is never placed has no GSR-Bench command and raises GSRError.
    """
    out: list[str] = []
    held: str | None = None
    for i, step in enumerate(steps, 1):
        name, args = step.action, step.args
        if name == "pick" and held is None and args:
            held = args[0]
        elif name in _MOVES and held is not None and len(args) == 2 and args[0] == held:
            out.append(f"move {held} {_MOVES[name]} {args[1]}")
            held = None
        elif name in ("open", "close") and held is None and len(args) == 1:
            out.append(f"{name} {args[0]}")
        else:
            raise GSRError(f"step {i} {step}: not expressible in GSR-Bench's actions (move, open, close)")
    if held is not None:
        raise GSRError(f"the plan ends holding {held}: GSR-Bench has no bare pick")
    return out
