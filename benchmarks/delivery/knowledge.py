"""The delivery agent's knowledge of a building as a scene graph: the map plus what it has seen so far.

It starts as ``building_graph(items=False)`` (floors, rooms, receptacles with their access keypoints,
connectors) and grows with every look: objects become nodes ``on``/``in`` their receptacle, people
become ``person`` nodes ``in`` the room they were seen in, with the time and place of the sighting.

This is a memory of sightings over a known map: nothing seen is ever dropped by a later look elsewhere,
only replaced when seen again or forgotten on purpose (a failed grasp, a person not where expected).
It is not the tabletop *object permanence* of ``gsr.perception.belief``, which merges one perceived
frame into the last and keeps an unseen object only when a closed container or an occluder explains
its absence (docs/architecture.md, "Where each concept lives").
"""

from __future__ import annotations

from dataclasses import dataclass

from gsr.benchmarks.delivery.building.graph import place_of_point, point_of_place
from gsr.benchmarks.delivery.building.model import Place
from gsr.benchmarks.delivery.reference import ObjectRef
from gsr.benchmarks.delivery.world import Observation

from gsr.scene_graph import Edge, Node, Pose, SceneGraph


@dataclass(frozen=True)
class ReceptacleInfo:
    """A receptacle as the map graph describes it."""

    id: str
    category: str
    room: str
    closed: bool
    relation: str
    place: Place  # its access keypoint as a grid place


class BuildingKnowledge:
    """Map knowledge plus observations, kept as one ``SceneGraph``."""

    def __init__(self, map_graph: SceneGraph, cell_size: float) -> None:
        """Index the map graph (rooms, receptacles) once."""
        self.graph = map_graph
        self.cell_size = cell_size
        support = {e.source: e.target for e in map_graph.edges if e.relation == "in"}
        self.room_kind: dict[str, str] = {}
        self.room_center: dict[str, tuple[int, float, float]] = {}
        self.receptacles: dict[str, ReceptacleInfo] = {}
        for n in map_graph.nodes:
            if support.get(n.id, "").startswith("floor_") and n.bbox is not None:
                self.room_kind[n.id] = n.category
                lo, hi = n.bbox.min, n.bbox.max
                floor = place_of_point(lo, cell_size)[0]
                self.room_center[n.id] = (
                    floor,
                    (lo.y + hi.y) / 2 / cell_size - 0.5,
                    (lo.x + hi.x) / 2 / cell_size - 0.5,
                )
        for n in map_graph.nodes:
            access = next((k for k in n.keypoints if k.name == "access"), None)
            if "holds" in n.attributes and access is not None and access.position is not None:
                self.receptacles[n.id] = ReceptacleInfo(
                    id=n.id,
                    category=n.category,
                    room=support[n.id],
                    closed="closed" in n.states,
                    relation=str(n.attributes["holds"]),
                    place=place_of_point(access.position, cell_size),
                )

    # ------------------------------------------------------------ updates

    def observe(self, obs: Observation) -> None:
        """Add what a look showed: objects on/in receptacles, people in the room (with time and place)."""
        nodes: dict[str, Node] = {n.id: n for n in self.graph.nodes}
        support: dict[str, Edge] = {}
        others: list[Edge] = []
        for e in self.graph.edges:
            if e.relation in ("on", "in") and (e.source in obs.items or e.source in obs.people):
                continue  # replaced below by what was just seen
            others.append(e)
        for iid, (category, color, rec) in obs.items.items():
            nodes[iid] = Node(id=iid, category=category, attributes={"color": color})
            support[iid] = Edge(source=iid, relation=self.receptacles[rec].relation, target=rec)
        for pid, place in obs.people.items():
            nodes[pid] = Node(
                id=pid,
                category="person",
                attributes={"seen_at": obs.time},
                pose=Pose(position=point_of_place(place, self.cell_size)),
            )
            if obs.room is not None:
                support[pid] = Edge(source=pid, relation="in", target=obs.room)
        self.graph = SceneGraph(
            nodes=tuple(nodes.values()), edges=(*others, *support.values()), metadata=self.graph.metadata
        )

    def forget(self, node_id: str) -> None:
        """Drop a node (an object the robot failed to grasp) and its edges."""
        self.graph = SceneGraph(
            nodes=tuple(n for n in self.graph.nodes if n.id != node_id),
            edges=tuple(e for e in self.graph.edges if node_id not in (e.source, e.target)),
            metadata=self.graph.metadata,
        )

    # ------------------------------------------------------------ queries

    def items_matching(self, ref: ObjectRef) -> list[tuple[str, str]]:
        """``(object id, receptacle id)`` of seen objects that fit the reference."""
        support = {e.source: e.target for e in self.graph.edges if e.relation in ("on", "in")}
        out = []
        for n in self.graph.nodes:
            rec = self.receptacles.get(support.get(n.id, ""))
            if rec is None or n.category != ref.category:
                continue
            if ref.color is not None and n.color != ref.color:
                continue
            if ref.receptacle is not None and rec.category != ref.receptacle:
                continue
            if ref.room is not None and rec.room != ref.room:
                continue
            out.append((n.id, rec.id))
        return out

    def sighting(self, person_id: str) -> tuple[float, Place] | None:
        """When and where a person was last seen, if ever."""
        if not self.graph.has_node(person_id):
            return None
        n = self.graph.node(person_id)
        if n.pose is None:
            return None
        return float(n.attributes["seen_at"]), place_of_point(n.pose.position, self.cell_size)
