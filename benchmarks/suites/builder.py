"""A small deterministic scene builder for generated suites: nodes, support edges and a table layout.

Objects get seeded table slots on a grid (front rows for movable things, the back row for fixtures);
anything placed on or in another object takes its holder's position, raised by the holder's height.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Any

from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.task_spec import Layout, PlacedObject

TABLE = "table"
#: Rough extents (m) per category, for stacking heights and the simulator's defaults.
SIZES: dict[str, tuple[float, float, float]] = {
    "cube": (0.05, 0.05, 0.05),
    "block": (0.05, 0.05, 0.05),
    "cup": (0.07, 0.07, 0.09),
    "mug": (0.08, 0.08, 0.09),
    "box": (0.20, 0.20, 0.12),
    "lidded_box": (0.20, 0.20, 0.12),
    "basket": (0.25, 0.18, 0.12),
    "tray": (0.30, 0.20, 0.03),
    "plate": (0.20, 0.20, 0.02),
    "bowl": (0.15, 0.15, 0.06),
    "cabinet": (0.30, 0.40, 0.45),
    "microwave": (0.30, 0.45, 0.28),
    "stove": (0.30, 0.45, 0.05),
    "shelf": (0.25, 0.50, 0.40),
    "rack": (0.20, 0.30, 0.10),
    "lamp": (0.15, 0.15, 0.35),
    "tap": (0.10, 0.10, 0.25),
}
FIXTURES = frozenset({"cabinet", "microwave", "stove", "shelf", "rack", "lamp", "tap"})


@dataclass
class SceneBuilder:
    """Accumulates nodes and support edges; ``build`` gives the graph and its layout."""

    seed: int
    nodes: list[Node] = field(default_factory=list)
    edges: list[Edge] = field(default_factory=list)
    rng: random.Random = field(init=False)

    def __post_init__(self) -> None:
        self.rng = random.Random(self.seed)
        self.nodes.append(Node(id=TABLE, category="table"))

    def add(
        self,
        node_id: str,
        category: str,
        *,
        color: str | None = None,
        states: tuple[str, ...] = (),
        on: str | None = TABLE,
        inside: str | None = None,
        parent: str | None = None,
        **attrs: Any,
    ) -> str:
        """Add an object (or a part with ``parent``) resting on ``on`` or in ``inside``; returns its id."""
        attributes: dict[str, Any] = dict(attrs)
        if color is not None:
            attributes["color"] = color
        self.nodes.append(
            Node(id=node_id, category=category, attributes=attributes, states=states, parent=parent)
        )
        if parent is None:
            if inside is not None:
                self.edges.append(Edge(source=node_id, relation="in", target=inside))
            elif on is not None:
                self.edges.append(Edge(source=node_id, relation="on", target=on))
        return node_id

    def cabinet(self, node_id: str = "cabinet", open_levels: tuple[int, ...] = ()) -> list[str]:
        """A cabinet with top/middle/bottom drawers (levels 2/1/0); returns the drawer ids top first."""
        self.add(node_id, "cabinet", movable=False)
        out = []
        for level, word in ((2, "top"), (1, "middle"), (0, "bottom")):
            state = "open" if level in open_levels else "closed"
            out.append(
                self.add(f"{node_id}/{word}_drawer", "drawer", parent=node_id, states=(state,), level=level)
            )
        return out

    def graph(self) -> SceneGraph:
        """The scene graph built so far."""
        return SceneGraph(nodes=tuple(self.nodes), edges=tuple(self.edges))

    def layout(self) -> Layout:
        """Seeded grid positions (m): movable objects on the front rows, fixtures on the back row."""
        support = {e.source: e.target for e in self.edges}
        front = [(x, y) for x in (-0.2, -0.08, 0.04) for y in (-0.45, -0.3, -0.15, 0.0, 0.15, 0.3, 0.45)]
        back = [(0.25, y) for y in (-0.4, -0.1, 0.2, 0.45, -0.25, 0.05, 0.35)]
        self.rng.shuffle(front)
        rng_back = back[:]
        placed: dict[str, PlacedObject] = {}
        parents = {n.id: n.parent for n in self.nodes}
        categories = {n.id: n.category for n in self.nodes}

        def root(holder: str) -> str:
            while parents.get(holder):
                holder = parents[holder]  # type: ignore[assignment]
            return holder

        def place(node: Node, depth: int = 0) -> None:
            if node.id in placed or node.parent is not None or node.id == TABLE:
                return
            holder = support.get(node.id, TABLE)
            size = SIZES.get(node.category)
            fixed = node.category in FIXTURES
            if holder != TABLE and depth < 10:
                base = root(holder)
                place(next(n for n in self.nodes if n.id == base), depth + 1)
                under = placed.get(base)
                bx, by, bz = under.position if under else (0.0, 0.0, 0.0)
                h = SIZES.get(categories.get(base, ""), (0, 0, 0.05))[2]
                pos = (bx, by, round(bz + (h if holder == base and node.category != "cube" else 0.02), 4))
            else:
                slots = rng_back if fixed else front
                x, y = slots.pop(0) if slots else (0.0, 0.0)
                pos = (x, y, 0.0)
            placed[node.id] = PlacedObject(
                id=node.id,
                asset="box_with_lid" if node.category == "lidded_box" else node.category,
                position=pos,
                color=node.color,
                size=size,
                fixed=fixed,
                on=None if holder == TABLE else holder,
            )

        for n in self.nodes:
            place(n)
        return Layout(objects=tuple(placed[n.id] for n in self.nodes if n.id in placed), seed=self.seed)
