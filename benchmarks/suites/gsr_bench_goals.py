"""GSR-Bench evaluation goals from the benchmark's query semantics (independent of gsr.language).

The published benchmark judges a run by the final scene graph; its task queries come in a handful of
forms, each with a fixed meaning that is encoded here as goal formulas over the config's node ids:

* ``move all [COLOR_]KINDs into TARGET`` — every matching object ends ``in`` TARGET (a box, a lidded box
  or a drawer named by its part name such as ``drawer_low``). Matching is by category and the primary
  ``color`` attribute (``yellow_mugs`` matches ``yellow_mug1`` but not ``white_yellow_mug``).
* ``... into their corresponding colored boxes`` — every listed-kind object of colour c ends in ``c_box``.
* ``... into different drawer layers`` — the named items each end in a drawer, no two in the same one:
  one goal alternative per injective assignment of items to drawers.
* ``... into the drawers by color — one color per drawer`` — all objects of one colour share a drawer and
  different colours use different drawers: one alternative per injective colour -> drawer assignment.
* ``put all items on the table into TARGET`` — every movable, non-container object resting on the table.
* lidded boxes (``red_lid_box``) are ordinary targets that must be opened; a query that also says
  "close" adds ``(not (open TARGET))``.

Goals are ground conjunctions (the matching set is fixed by the initial graph), so partial credit is
the fraction of satisfied ``in`` relations of the best alternative.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

from gsr.categories import get_category, is_a
from gsr.errors import GSRError
from gsr.facts import node_affordances
from gsr.scene_graph import Node, SceneGraph

#: Cap on enumerated alternatives (3 drawers x 3 colours gives 6).
MAX_ALTERNATIVES = 120
_KIND_WORDS = {"cubes": "cube", "mugs": "mug", "boxes": "box", "books": "book", "bowls": "bowl"}


@dataclass(frozen=True)
class GoalSpec:
    """The goal alternatives for one query (the first is the canonical goal) and what kind of query it was."""

    kind: str
    alternatives: tuple[str, ...]
    objects: tuple[str, ...]


def _conj(pairs: list[tuple[str, str]], extra: tuple[str, ...] = ()) -> str:
    parts = [f"(in {o} {t})" for o, t in pairs] + list(extra)
    return "(and " + " ".join(parts) + ")"


def _objects(graph: SceneGraph) -> list[Node]:
    """Movable whole objects (not parts, not fixtures)."""
    return [n for n in graph.nodes if n.parent is None and "movable" in node_affordances(n)]


def _drawers(graph: SceneGraph) -> list[Node]:
    return [n for n in graph.nodes if is_a(n.category, "drawer")]


def _matches(node: Node, kind: str, color: str | None) -> bool:
    base = get_category(kind).name
    if not is_a(node.category, base):
        return False
    return color is None or node.attributes.get("color") == color


def _parse_what(text: str) -> tuple[str, str | None]:
    """``red_cubes`` -> (``cube``, ``red``); ``mugs`` -> (``mug``, None)."""
    word = text.strip().lower().replace(" ", "_")
    color = None
    if "_" in word:
        color, word = word.split("_", 1)
    kind = _KIND_WORDS.get(word, word[:-1] if word.endswith("s") else word)
    return kind, color


def resolve_target(graph: SceneGraph, name: str) -> str:
    """The node a query's target word names: an exact id or a part's last segment (``drawer_low``)."""
    name = name.strip().lower().replace(" ", "_")
    ids = [n.id for n in graph.nodes]
    if name in ids:
        return name
    parts = [i for i in ids if i.rsplit("/", 1)[-1] == name]
    if len(parts) == 1:
        return parts[0]
    if len(parts) > 1:
        raise GSRError(f"target {name!r} is ambiguous: {', '.join(parts)}")
    raise GSRError(f"target {name!r} is not a node of the scene graph")


def _kinds_in(query: str) -> list[str]:
    found = [k for w, k in _KIND_WORDS.items() if re.search(rf"\b{w}\b", query)]
    return found or ["cube", "mug"]


def _move_all(graph: SceneGraph, query: str, m: re.Match[str]) -> GoalSpec:
    kind, color = _parse_what(m.group("what"))
    target = resolve_target(graph, m.group("target"))
    objs = [n.id for n in _objects(graph) if n.id != target and _matches(n, kind, color)]
    if not objs:
        raise GSRError(f"no object matches {m.group('what')!r}")
    extra = (f"(not (open {target}))",) if re.search(r"\bclose\b", query) else ()
    return GoalSpec("move_all", (_conj([(o, target) for o in objs], extra),), tuple(objs))


def _corresponding_boxes(graph: SceneGraph, query: str) -> GoalSpec:
    kinds = _kinds_in(query)
    boxes = {
        n.attributes.get("color"): n.id
        for n in graph.nodes
        if is_a(n.category, "box") and n.attributes.get("color") is not None
    }
    pairs = []
    for n in _objects(graph):
        color = n.attributes.get("color")
        if any(_matches(n, k, None) for k in kinds) and color in boxes and boxes[color] != n.id:
            pairs.append((n.id, boxes[color]))
    if not pairs:
        raise GSRError("no object has a box of its colour")
    return GoalSpec("corresponding_boxes", (_conj(pairs),), tuple(o for o, _ in pairs))


def _item_nodes(graph: SceneGraph, names: list[str]) -> list[str]:
    out = []
    objs = _objects(graph)
    for raw in names:
        word = raw.strip().lower().replace(" ", "_")
        exact = [n.id for n in objs if n.id == word]
        by_kind = [n.id for n in objs if is_a(n.category, get_category(word).name) and word != "thing"]
        hit = exact or by_kind
        if len(hit) != 1:
            what = "no object" if not hit else f"{len(hit)} objects ({', '.join(hit)})"
            raise GSRError(f"item {raw!r} names {what}")
        out.append(hit[0])
    return out


def _assignments(keys: list[str], drawers: list[str]) -> list[dict[str, str]]:
    if len(keys) > len(drawers):
        raise GSRError(f"{len(keys)} groups but only {len(drawers)} drawers")
    out = [dict(zip(keys, perm, strict=True)) for perm in itertools.permutations(drawers, len(keys))]
    return out[:MAX_ALTERNATIVES]


def _different_layers(graph: SceneGraph, query: str, m: re.Match[str]) -> GoalSpec:
    names = [w for w in re.split(r",|\band\b", m.group("items")) if w.strip()]
    names = [re.sub(r"^\s*(the|a|an)\s+", "", w).strip() for w in names]
    items = _item_nodes(graph, names)
    drawers = [d.id for d in _drawers(graph)]
    alts = [_conj([(i, a[i]) for i in items]) for a in _assignments(items, drawers)]
    return GoalSpec("different_drawers", tuple(alts), tuple(items))


def _color_per_drawer(graph: SceneGraph, query: str) -> GoalSpec:
    kinds = _kinds_in(query)
    groups: dict[str, list[str]] = {}
    for n in _objects(graph):
        color = n.attributes.get("color")
        if isinstance(color, str) and any(_matches(n, k, None) for k in kinds):
            groups.setdefault(color, []).append(n.id)
    if not groups:
        raise GSRError("no object to sort by colour")
    colors = sorted(groups)
    drawers = [d.id for d in _drawers(graph)]
    alts = [_conj([(o, a[c]) for c in colors for o in groups[c]]) for a in _assignments(colors, drawers)]
    return GoalSpec("color_per_drawer", tuple(alts), tuple(o for c in colors for o in groups[c]))


def _items_on_table(graph: SceneGraph, query: str, m: re.Match[str]) -> GoalSpec:
    target = resolve_target(graph, m.group("target"))
    on_table = {
        e.source for e in graph.edges if e.relation == "on" and is_a(graph.node(e.target).category, "table")
    }
    objs = [
        n.id
        for n in _objects(graph)
        if n.id in on_table and n.id != target and "container" not in node_affordances(n)
    ]
    if not objs:
        raise GSRError("no item on the table")
    extra = (f"(not (open {target}))",) if re.search(r"\bclose\b", query) else ()
    return GoalSpec("items_on_table", (_conj([(o, target) for o in objs], extra),), tuple(objs))


_MOVE_ALL = re.compile(
    r"\b(?:move|put|place)\s+all\s+(?:the\s+)?(?P<what>[a-z_]+?)\s+(?:in|into|to)\s+(?:the\s+)?(?P<target>[a-z0-9_/]+)"
)
_TABLE_ITEMS = re.compile(
    r"\ball\s+(?:the\s+)?(?:items|objects|things)\s+on\s+the\s+table\s+(?:in|into|to)\s+(?:the\s+)?(?P<target>[a-z0-9_/]+)"
)
_LAYERS = re.compile(r"(?:put|place|move)\s+(?P<items>.+?)\s+into\s+different\s+drawer")


def goal_for_query(graph: SceneGraph, query: str) -> GoalSpec:
    """The evaluation goal alternatives of a GSR-Bench ``task_query`` on its initial graph."""
    q = " ".join(query.lower().replace("—", " - ").split()).rstrip(".")
    if "corresponding" in q and "box" in q:
        return _corresponding_boxes(graph, q)
    if "one color per drawer" in q or "one colour per drawer" in q:
        return _color_per_drawer(graph, q)
    m = _LAYERS.search(q)
    if m and "layer" in q:
        return _different_layers(graph, q, m)
    m = _TABLE_ITEMS.search(q)
    if m:
        return _items_on_table(graph, q, m)
    m = _MOVE_ALL.search(q)
    if m:
        return _move_all(graph, q, m)
    raise GSRError(f"unsupported GSR-Bench task query {query!r}")
