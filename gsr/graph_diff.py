"""What changed between two scene graphs: nodes, edges, states and attributes."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from gsr.scene_graph import SceneGraph

EdgeKey = tuple[str, str, str]


@dataclass(frozen=True, slots=True)
class GraphDiff:
    """The difference ``b - a``; every collection is sorted, so equal diffs compare and print equal."""

    added_nodes: tuple[str, ...] = ()
    removed_nodes: tuple[str, ...] = ()
    added_edges: tuple[EdgeKey, ...] = ()
    removed_edges: tuple[EdgeKey, ...] = ()
    # node id -> (states in a only, states in b only)
    state_changes: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = field(default_factory=dict)
    # node id -> {attribute: (value in a or None, value in b or None)}
    attribute_changes: dict[str, dict[str, tuple[Any, Any]]] = field(default_factory=dict)
    # node id -> {"category" | "parent": (old, new)}
    node_changes: dict[str, dict[str, tuple[Any, Any]]] = field(default_factory=dict)

    @property
    def is_empty(self) -> bool:
        """True when the graphs agree on nodes, edges (as sets), states and attributes."""
        return not (
            self.added_nodes
            or self.removed_nodes
            or self.added_edges
            or self.removed_edges
            or self.state_changes
            or self.attribute_changes
            or self.node_changes
        )

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "added_nodes": list(self.added_nodes),
            "removed_nodes": list(self.removed_nodes),
            "added_edges": [list(e) for e in self.added_edges],
            "removed_edges": [list(e) for e in self.removed_edges],
            "state_changes": {
                k: {"removed": list(a), "added": list(b)} for k, (a, b) in self.state_changes.items()
            },
            "attribute_changes": {
                k: {attr: [old, new] for attr, (old, new) in v.items()}
                for k, v in self.attribute_changes.items()
            },
            "node_changes": {
                k: {f: [old, new] for f, (old, new) in v.items()} for k, v in self.node_changes.items()
            },
        }

    def __str__(self) -> str:
        if self.is_empty:
            return "no changes"
        lines: list[str] = []
        lines += [f"+ node {n}" for n in self.added_nodes]
        lines += [f"- node {n}" for n in self.removed_nodes]
        lines += [f"- {s} {r} {t}" for s, r, t in self.removed_edges]
        lines += [f"+ {s} {r} {t}" for s, r, t in self.added_edges]
        for node, (old, new) in self.state_changes.items():
            was = ", ".join(old) or "-"
            now = ", ".join(new) or "-"
            lines.append(f"~ {node}: {was} -> {now}")
        for node, attrs in self.attribute_changes.items():
            for attr, (old, new) in attrs.items():
                lines.append(f"~ {node}.{attr}: {old!r} -> {new!r}")
        for node, fields in self.node_changes.items():
            for f, (old, new) in fields.items():
                lines.append(f"~ {node}.{f}: {old!r} -> {new!r}")
        return "\n".join(lines)


def diff_graphs(a: SceneGraph, b: SceneGraph) -> GraphDiff:
    """The changes that turn graph ``a`` into graph ``b``."""
    na, nb = a.node_map(), b.node_map()
    ea = {e.key() for e in a.edges}
    eb = {e.key() for e in b.edges}
    states: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {}
    attrs: dict[str, dict[str, tuple[Any, Any]]] = {}
    fields: dict[str, dict[str, tuple[Any, Any]]] = {}
    for node_id in sorted(na.keys() & nb.keys()):
        x, y = na[node_id], nb[node_id]
        if set(x.states) != set(y.states):
            states[node_id] = (
                tuple(sorted(set(x.states) - set(y.states))),
                tuple(sorted(set(y.states) - set(x.states))),
            )
        changed = {
            k: (x.attributes.get(k), y.attributes.get(k))
            for k in sorted(x.attributes.keys() | y.attributes.keys())
            if x.attributes.get(k) != y.attributes.get(k)
        }
        if changed:
            attrs[node_id] = changed
        moved = {
            f: (getattr(x, f), getattr(y, f))
            for f in ("category", "parent")
            if getattr(x, f) != getattr(y, f)
        }
        if moved:
            fields[node_id] = moved
    return GraphDiff(
        added_nodes=tuple(sorted(nb.keys() - na.keys())),
        removed_nodes=tuple(sorted(na.keys() - nb.keys())),
        added_edges=tuple(sorted(eb - ea)),
        removed_edges=tuple(sorted(ea - eb)),
        state_changes=states,
        attribute_changes=attrs,
        node_changes=fields,
    )
