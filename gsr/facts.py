"""Scene graph <-> symbolic state for the tabletop domain.

A scene graph entails a set of ground atoms: the static facts its categories afford
(``(container blue_box)``), its structure (``(part_of short_cabinet/drawer_low short_cabinet)``,
``(above short_cabinet/drawer_high short_cabinet/drawer_low)`` from drawer ``level`` attributes),
colours, support edges (``on``/``in``), node states (open, on, held) and the derived cube counters
``(cube_count c nK)``. :func:`graph_with_state` goes the other way for the dynamic part.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable

from gsr.categories import COLORS, affordances, ancestors, get_category, is_part_category
from gsr.pddl.model import Atom, Domain, Formula, Problem
from gsr.resources import load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.state import State

#: Largest cube count the domain represents (``n0`` .. ``n10``).
MAX_COUNT = 10
COUNTS: tuple[str, ...] = tuple(f"n{i}" for i in range(MAX_COUNT + 1))

#: Predicates whose truth comes from the graph's dynamic part (edges and node states).
DYNAMIC_PREDICATES = frozenset({"on", "in", "open", "turned_on", "holding", "hand_empty"})
HAND_EMPTY = Atom("hand_empty", ())
#: Node states that :func:`graph_with_state` rewrites.
DYNAMIC_STATES = frozenset({"open", "closed", "on", "off", "held"})


def default_domain() -> Domain:
    return load_builtin_domain("tabletop")


def node_affordances(node: Node) -> frozenset[str]:
    """Affordances of a node: its category's, adjusted by attributes (parts never movable, ``lid``)."""
    aff = set(affordances(node.category))
    if node.parent is not None or is_part_category(node.category):
        aff.discard("movable")
        aff.discard("pushable")
    if node.attributes.get("lid") is True:
        aff.add("openable")
    for key in ("openable", "container", "supporter", "movable", "switchable", "pressable", "pushable"):
        value = node.attributes.get(key)
        if isinstance(value, bool):  # explicit per-node override
            (aff.add if value else aff.discard)(key)
    return frozenset(aff)


def node_colors(node: Node) -> tuple[str, ...]:
    """Palette colours of a node (``color`` then ``secondary_color`` attributes)."""
    out = []
    for key in ("color", "secondary_color"):
        c = node.attributes.get(key)
        if isinstance(c, str) and c.lower() in COLORS and c.lower() not in out:
            out.append(c.lower())
    return tuple(out)


def _drawer_level(node: Node) -> int | None:
    level = node.attributes.get("level")
    if isinstance(level, bool) or not isinstance(level, int | float):
        return None
    return int(level)


#: Graph metadata key naming the rule set of the scene's world (``gsr-bench``: GSR-Bench's validator).
RULES_KEY = "rules"
#: Categories of the surfaces everything stands on; only there may a GSR-Bench cube be picked from ``on``.
BASE_SURFACES = frozenset({"table", "floor"})


def static_facts(graph: SceneGraph) -> frozenset[Atom]:
    """Affordances, colours, part_of, drawer ``above`` relations and the counter successor facts.

    Also ``(base_surface x)`` for tables and floors, ``(full x)`` for a node in state ``full`` (a
    GSR-Bench ``0=F`` table) and, when the graph's ``rules`` metadata is ``gsr-bench``,
    ``(receives_uncovered x)`` for every other supporter: GSR-Bench accepts nothing onto a target
    that has something on top.
    """
    atoms: set[Atom] = {Atom("next", (a, b)) for a, b in itertools.pairwise(COUNTS)}
    gsr_bench = graph.metadata.get(RULES_KEY) == "gsr-bench"
    for n in graph.nodes:
        aff = node_affordances(n)
        atoms.update(Atom(a, (n.id,)) for a in aff)
        base = n.category in BASE_SURFACES or bool(BASE_SURFACES & set(ancestors(n.category)))
        if base:
            atoms.add(Atom("base_surface", (n.id,)))
        elif gsr_bench and "supporter" in aff:
            atoms.add(Atom("receives_uncovered", (n.id,)))
        if "full" in n.states:
            atoms.add(Atom("full", (n.id,)))
        atoms.update(Atom("has_color", (n.id, c)) for c in node_colors(n))
        if n.parent is not None:
            atoms.add(Atom("part_of", (n.id, n.parent)))
    # a drawer is reachable only while the drawers above it (same cabinet, higher level) are closed
    levelled: dict[str, list[tuple[int, str]]] = {}
    for n in graph.nodes:
        level = _drawer_level(n)
        if n.parent is not None and level is not None and "openable" in node_affordances(n):
            levelled.setdefault(n.parent, []).append((level, n.id))
    for drawers in levelled.values():
        for lu, upper in drawers:
            for ll, lower in drawers:
                if lu > ll:
                    atoms.add(Atom("above", (upper, lower)))
    return frozenset(atoms)


def dynamic_facts(graph: SceneGraph) -> frozenset[Atom]:
    """Support edges and node states as atoms (``on``, ``in``, ``open``, ``turned_on``, ``holding``, ``hand_empty``)."""
    atoms: set[Atom] = set()
    for e in graph.edges:
        if e.relation in ("on", "in"):
            atoms.add(Atom(e.relation, (e.source, e.target)))
    for n in graph.nodes:
        if "open" in n.states:
            atoms.add(Atom("open", (n.id,)))
        if "on" in n.states:
            atoms.add(Atom("turned_on", (n.id,)))
        if "held" in n.states:
            atoms.add(Atom("holding", (n.id,)))
    if not any(a.predicate == "holding" for a in atoms):
        atoms.add(HAND_EMPTY)  # the arm's state is a fluent: an exists-not-holding axiom explodes FD
    return frozenset(atoms)


def cube_counts(graph: SceneGraph) -> frozenset[Atom]:
    """``(cube_count c nK)`` for every container: K counted objects (cubes) are in it, capped at 10."""
    nodes = graph.node_map()
    counts = {n.id: 0 for n in graph.nodes if "container" in node_affordances(n)}
    for e in graph.edges:
        if e.relation == "in" and e.target in counts and "counted" in node_affordances(nodes[e.source]):
            counts[e.target] += 1
    return frozenset(Atom("cube_count", (c, COUNTS[min(k, MAX_COUNT)])) for c, k in counts.items())


def facts(graph: SceneGraph) -> frozenset[Atom]:
    """All ground atoms the graph entails: static, dynamic and the derived cube counters."""
    return static_facts(graph) | dynamic_facts(graph) | cube_counts(graph)


def object_type(node: Node, domain: Domain) -> str:
    """The PDDL type of a node: its category if the domain declares it, else the nearest declared ancestor."""
    for t in (get_category(node.category).name, node.category, *ancestors(node.category)):
        if t in domain.types:
            return t
    return "thing" if "thing" in domain.types else "object"


def graph_objects(graph: SceneGraph, domain: Domain) -> dict[str, str]:
    """Problem objects: node id -> PDDL type."""
    return {n.id: object_type(n, domain) for n in graph.nodes}


def state_from_graph(graph: SceneGraph, domain: Domain | None = None) -> State:
    """The symbolic state a graph entails; objects are the nodes (typed) plus the domain's constants."""
    domain = domain or default_domain()
    objects = dict(domain.constants)
    objects.update(graph_objects(graph, domain))
    return State(facts(graph), objects)


def problem_from_graph(
    graph: SceneGraph, goal: Formula, name: str = "task", domain: Domain | None = None
) -> Problem:
    """A PDDL problem: the graph's objects and facts as the initial state, with this goal."""
    domain = domain or default_domain()
    return Problem(
        name=name,
        domain_name=domain.name,
        objects=graph_objects(graph, domain),
        init=facts(graph),
        goal=goal,
    )


def graph_with_state(graph: SceneGraph, state: State | Iterable[Atom]) -> SceneGraph:
    """The graph with its dynamic part (on/in edges, open/closed, on/off, held) rewritten from the atoms.

    Node ids, categories, attributes, poses and non-support edges are kept, except that descriptive
    relations (``left_of`` ...) of an object whose support changed are dropped: they no longer hold.
    Static and derived atoms (affordances, counters) are ignored.
    """
    atoms = state.atoms if isinstance(state, State) else frozenset(state)
    ids = {n.id for n in graph.nodes}
    support = {
        (a.predicate, *a.args)
        for a in atoms
        if a.predicate in ("on", "in") and len(a.args) == 2 and a.args[0] in ids and a.args[1] in ids
    }
    old_support = {(e.relation, e.source, e.target) for e in graph.edges if e.relation in ("on", "in")}
    moved = {s for (_, s, _) in support ^ old_support}
    opened = {a.args[0] for a in atoms if a.predicate == "open" and a.args}
    powered = {a.args[0] for a in atoms if a.predicate == "turned_on" and a.args}
    held = {a.args[0] for a in atoms if a.predicate == "holding" and a.args}
    moved |= held

    edges: list[Edge] = []
    for e in graph.edges:
        if e.relation in ("on", "in"):
            if (e.relation, e.source, e.target) in support:
                edges.append(e)
        elif e.source not in moved and e.target not in moved:
            edges.append(e)
    for rel, s, t in sorted(support - old_support):
        edges.append(Edge(source=s, relation=rel, target=t))

    nodes = [_node_with_states(n, opened, powered, held) for n in graph.nodes]
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges), metadata=graph.metadata)


def _node_with_states(node: Node, opened: set[str], powered: set[str], held: set[str]) -> Node:
    aff = node_affordances(node)
    states = set(node.states) - DYNAMIC_STATES
    had = set(node.states)
    if node.id in opened:
        states.add("open")
    elif "openable" in aff and had & {"open", "closed"}:
        states.add("closed")  # only name the default (closed) where the graph already named a door state
    if node.id in powered:
        states.add("on")
    elif "switchable" in aff and had & {"on", "off"}:
        states.add("off")
    if node.id in held:
        states.add("held")
    if states == had:
        return node
    return node.model_copy(update={"states": tuple(sorted(states))})
