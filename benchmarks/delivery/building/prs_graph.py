"""The PRS station as a ``SceneGraph``: building -> floors -> rooms / corridors -> receptacles -> objects.

Edges: ``floor in building``, ``room in floor``, ``corridor in floor``, ``receptacle in room``, ``object on
receptacle`` (or ``object in room`` when it rests on none), ``person in room``; rooms whose free cells
touch (a doorway) are ``adjacent``, and so is a room with each corridor its free cells open onto. Geometry
is in PRS's world frame where the floor is calibrated (``bbox`` in metres: x, y up, z), else absent.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from gsr.benchmarks.delivery.building.prs_station import Station
from scipy import ndimage

from gsr.scene_graph import BoundingBox, Edge, Node, SceneGraph, Vec3


def corridor_labels(station: Station, level: int) -> np.ndarray:
    """Connected components (4-connected) of the free cells that lie in no room; 0 = not corridor."""
    f = station.floors[level]
    labels, _ = ndimage.label(f.walkable & (f.room_of < 0))
    return labels


def room_adjacency(station: Station) -> set[tuple[str, str]]:
    """Unordered pairs of places (room ids, ``F<level>.corridor<k>``) whose free cells touch."""
    pairs: set[tuple[str, str]] = set()
    for level, f in station.floors.items():
        corr = corridor_labels(station, level)
        place = np.full(f.grid.shape, "", dtype=object)
        for k, r in enumerate(station.rooms):
            if r.floor == level:
                place[(f.room_of == k) & f.walkable] = r.id
        place[corr > 0] = np.char.add(f"F{level}.corridor", corr[corr > 0].astype(str)).astype(object)
        for da, db in ((1, 0), (0, 1)):
            a = place[: place.shape[0] - da, : place.shape[1] - db]
            b = place[da:, db:]
            mask = (a != "") & (b != "") & (a != b)
            for x, y in zip(a[mask], b[mask], strict=True):
                pairs.add((min(x, y), max(x, y)))
    return pairs


def _bbox(station: Station, level: int, box: tuple[int, int, int, int], height: float) -> BoundingBox | None:
    t = station.floors[level].transform
    if t is None:
        return None
    x0, z0 = t.to_world(box[0] - 0.5, box[2] - 0.5)
    x1, z1 = t.to_world(box[1] + 0.5, box[3] + 0.5)
    return BoundingBox(
        min=Vec3(x=min(x0, x1), y=t.height, z=min(z0, z1)),
        max=Vec3(x=max(x0, x1), y=t.height + height, z=max(z0, z1)),
    )


def station_graph(
    station: Station,
    objects: Iterable[dict] = (),
    people_rooms: dict[int, str] | None = None,
) -> SceneGraph:
    """The station's scene graph. ``objects``: dicts with ``id``, ``category``, ``room`` and ``receptacle``
    (ids or None); ``people_rooms``: person id -> room id for the people to include."""
    nodes = [Node(id="station", category="building", attributes={"name": "PRS station"})]
    edges: list[Edge] = []
    for level in sorted(station.floors):
        fid = f"floor_{level}"
        t = station.floors[level].transform
        attrs: dict[str, str | float | int | bool] = {"level": level, "calibrated": t is not None}
        if t is not None:
            attrs.update({"x0": t.x0, "z0": t.z0, "cell_m": t.scale, "height": t.height})
        nodes.append(Node(id=fid, category="floor", attributes=attrs))
        edges.append(Edge(source=fid, relation="in", target="station"))
        for k in range(1, int(corridor_labels(station, level).max()) + 1):
            cid = f"F{level}.corridor{k}"
            nodes.append(Node(id=cid, category="corridor", attributes={"floor": level}))
            edges.append(Edge(source=cid, relation="in", target=fid))
    for r in station.rooms:
        nodes.append(
            Node(
                id=r.id,
                category="room",
                attributes={"name": r.name, "floor": r.floor},
                bbox=_bbox(station, r.floor, r.box, 3.0),
            )
        )
        edges.append(Edge(source=r.id, relation="in", target=f"floor_{r.floor}"))
    for a, b in sorted(room_adjacency(station)):
        edges += [
            Edge(source=a, relation="adjacent", target=b),
            Edge(source=b, relation="adjacent", target=a),
        ]
    for rec in station.receptacles:
        nodes.append(
            Node(
                id=rec.id,
                category="receptacle",
                attributes={"name": rec.name, "floor": rec.floor},
                bbox=_bbox(station, rec.floor, rec.box, 0.8),
            )
        )
        if rec.room:
            edges.append(Edge(source=rec.id, relation="in", target=rec.room))
    for o in objects:
        nodes.append(Node(id=o["id"], category=o["category"]))
        if o.get("receptacle"):
            edges.append(Edge(source=o["id"], relation="on", target=o["receptacle"]))
        elif o.get("room"):
            edges.append(Edge(source=o["id"], relation="in", target=o["room"]))
    for pid, room in sorted((people_rooms or {}).items()):
        p = station.people[pid]
        nodes.append(Node(id=f"person_{pid}", category="person", attributes={"appearance": p.character}))
        edges.append(Edge(source=f"person_{pid}", relation="in", target=room))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges), metadata={"building": "PRS station"})
