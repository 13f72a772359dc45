"""The grounded scene graph: objects, articulated parts, states and typed spatial relations.

A ``SceneGraph`` is the one state representation that flows through GSR. It is a pydantic
model (JSON round trip, JSON Schema) with a ``networkx.MultiDiGraph`` view. Node ids are
PDDL-safe names; a part's id conventionally is ``parent/part`` (``short_cabinet/drawer_low``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from gsr.errors import GSRError

if TYPE_CHECKING:
    import networkx as nx

#: Spatial / support relations an edge may carry. ``on`` and ``in`` are support relations
#: (at most one support per object); the others are descriptive.
RELATIONS: tuple[str, ...] = (
    "on",
    "in",
    "adjacent",
    "left_of",
    "right_of",
    "front_of",
    "behind",
    "under",
    "above",
    "near",
    "connects",
)
SUPPORT_RELATIONS: frozenset[str] = frozenset({"on", "in"})

#: What a node id, category or parent may look like (lower case; ``/`` separates an object and its part).
NODE_NAME = re.compile(r"^[a-z][a-z0-9_\-./]*$")


class Vec3(BaseModel):
    """A point or vector in metres."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    x: float
    y: float
    z: float

    def as_tuple(self) -> tuple[float, float, float]:
        """``(x, y, z)``."""
        return (self.x, self.y, self.z)


class Pose(BaseModel):
    """Position (metres) and orientation (quaternion x, y, z, w) in the world frame."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    position: Vec3
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)


class BoundingBox(BaseModel):
    """Axis-aligned bounding box in the world frame."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    min: Vec3
    max: Vec3

    @model_validator(mode="after")
    def _ordered(self) -> BoundingBox:
        if any(a > b for a, b in zip(self.min.as_tuple(), self.max.as_tuple(), strict=True)):
            raise ValueError("bounding box min must not exceed max on any axis")
        return self


class Keypoint(BaseModel):
    """A functional keypoint such as a mug's handle or a drawer's pull."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str
    position: Vec3 | None = None


class Node(BaseModel):
    """An object or an articulated part (a part has ``parent``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    id: str
    category: str
    attributes: dict[str, str | float | int | bool] = Field(default_factory=dict)
    states: tuple[str, ...] = ()
    parent: str | None = None
    keypoints: tuple[Keypoint, ...] = ()
    pose: Pose | None = None
    bbox: BoundingBox | None = None

    @field_validator("id", "category")
    @classmethod
    def _name(cls, v: str) -> str:
        v = v.lower()
        if not NODE_NAME.match(v):
            raise ValueError(f"{v!r} is not a valid name (letters, digits, _ - . /; starting with a letter)")
        return v

    @field_validator("states")
    @classmethod
    def _states(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(sorted({s.lower() for s in v}))

    @property
    def color(self) -> str | None:
        """The ``color`` attribute, if any."""
        c = self.attributes.get("color")
        return str(c) if c is not None else None


class Edge(BaseModel):
    """A typed relation ``source --relation--> target`` (``red_cube1 on table``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    source: str
    relation: str
    target: str

    @field_validator("relation")
    @classmethod
    def _relation(cls, v: str) -> str:
        v = v.lower()
        if v not in RELATIONS:
            raise ValueError(f"unknown relation {v!r}; expected one of {', '.join(RELATIONS)}")
        return v

    @field_validator("source", "target")
    @classmethod
    def _lower(cls, v: str) -> str:
        return v.lower()

    def key(self) -> tuple[str, str, str]:
        """``(source, relation, target)``."""
        return (self.source, self.relation, self.target)


class SceneGraph(BaseModel):
    """Nodes and typed edges. Node ids are unique; every edge and parent refers to a node."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    nodes: tuple[Node, ...] = ()
    edges: tuple[Edge, ...] = ()
    metadata: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _consistent(self) -> SceneGraph:
        ids: set[str] = set()
        for n in self.nodes:
            if n.id in ids:
                raise ValueError(f"duplicate node id {n.id!r}")
            ids.add(n.id)
        for n in self.nodes:
            if n.parent is not None and n.parent not in ids:
                raise ValueError(f"node {n.id!r} has parent {n.parent!r}, which is not a node")
        seen: set[tuple[str, str, str]] = set()
        for e in self.edges:
            for end in (e.source, e.target):
                if end not in ids:
                    raise ValueError(
                        f"edge {e.source} -{e.relation}-> {e.target} refers to unknown node {end!r}"
                    )
            if e.source == e.target:
                raise ValueError(f"edge {e.source} -{e.relation}-> {e.target} is a self-loop")
            if e.key() in seen:
                raise ValueError(f"duplicate edge {e.source} -{e.relation}-> {e.target}")
            seen.add(e.key())
        return self

    # ------------------------------------------------------------ access

    def node(self, node_id: str) -> Node:
        """The node with this id; ``KeyError`` naming it if absent."""
        for n in self.nodes:
            if n.id == node_id:
                return n
        raise KeyError(f"no node {node_id!r} in the scene graph")

    def has_node(self, node_id: str) -> bool:
        """True when a node with this id exists."""
        return any(n.id == node_id for n in self.nodes)

    def node_map(self) -> dict[str, Node]:
        """Nodes by id."""
        return {n.id: n for n in self.nodes}

    def edges_from(self, node_id: str, relation: str | None = None) -> Iterator[Edge]:
        """Outgoing edges of a node, optionally of one relation."""
        return (e for e in self.edges if e.source == node_id and (relation is None or e.relation == relation))

    def edges_to(self, node_id: str, relation: str | None = None) -> Iterator[Edge]:
        """Incoming edges of a node, optionally of one relation."""
        return (e for e in self.edges if e.target == node_id and (relation is None or e.relation == relation))

    def support(self, node_id: str) -> Edge | None:
        """The ``on``/``in`` edge that holds a node up, or ``None`` (a root such as the table, or a part).

        A well-formed graph has at most one; if a malformed one lists several, the last one counts (as in
        :meth:`supports`)."""
        found = None
        for e in self.edges:
            if e.source == node_id and e.relation in SUPPORT_RELATIONS:
                found = e
        return found

    def supports(self) -> dict[str, Edge]:
        """Every supported node's ``on``/``in`` edge, by node id (one pass over the edges)."""
        return {e.source: e for e in self.edges if e.relation in SUPPORT_RELATIONS}

    def parts(self, node_id: str) -> list[Node]:
        """The articulated parts whose parent is ``node_id``."""
        return [n for n in self.nodes if n.parent == node_id]

    # ------------------------------------------------------------ edits (return new graphs)

    def with_nodes(self, nodes: Iterable[Node]) -> SceneGraph:
        """A copy with these nodes replacing same-id nodes (or appended)."""
        new = {n.id: n for n in nodes}
        kept = [new.pop(n.id, n) for n in self.nodes]
        return SceneGraph(nodes=(*kept, *new.values()), edges=self.edges, metadata=self.metadata)

    def with_edges(self, edges: Iterable[Edge]) -> SceneGraph:
        """A copy with exactly these edges."""
        return SceneGraph(nodes=self.nodes, edges=tuple(edges), metadata=self.metadata)

    # ------------------------------------------------------------ views and IO

    def to_networkx(self) -> nx.MultiDiGraph:
        """A ``networkx.MultiDiGraph``: node attributes from the model, edge key = relation."""
        import networkx as nx

        g = nx.MultiDiGraph()
        for n in self.nodes:
            g.add_node(n.id, **n.model_dump(exclude={"id"}))
        for e in self.edges:
            g.add_edge(e.source, e.target, key=e.relation, relation=e.relation)
        return g

    def to_json(self, indent: int | None = 2) -> str:
        """JSON text (omits unset optional fields)."""
        return self.model_dump_json(indent=indent, exclude_defaults=True)

    @classmethod
    def from_json(cls, text: str, source: str = "<string>") -> SceneGraph:
        """Parse JSON text; errors name the source and the offending field."""
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise GSRError(f"{source}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
        return cls.from_data(data, source)

    @classmethod
    def from_data(cls, data: Any, source: str = "<data>") -> SceneGraph:
        """Validate a decoded JSON object into a graph, with a readable error."""
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise GSRError(f"{source}: invalid scene graph: {format_validation_error(exc)}") from None

    @classmethod
    def load(cls, path: str | Path) -> SceneGraph:
        """Read a scene-graph JSON file."""
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except OSError as exc:
            raise GSRError(f"{p}: cannot read: {exc.strerror}") from None
        if not text.strip():
            raise GSRError(f"{p}: file is empty")
        return cls.from_json(text, str(p))


def format_validation_error(exc: ValidationError) -> str:
    """One line per problem: ``field.path: message``."""
    lines = []
    for err in exc.errors():
        loc = ".".join(str(p) for p in err["loc"]) or "<root>"
        msg = err["msg"].removeprefix("Value error, ")
        lines.append(f"{loc}: {msg}")
    return "; ".join(lines)


def scene_graph_schema() -> dict[str, Any]:
    """The JSON Schema of ``SceneGraph``."""
    return SceneGraph.model_json_schema()
