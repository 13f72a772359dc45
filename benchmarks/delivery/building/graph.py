"""A building as a hierarchical ``SceneGraph``: building -> floors -> rooms -> receptacles -> objects.

Support edges run down the hierarchy (``floor in building``, ``room in floor``, ``receptacle in room``,
``object on|in receptacle``, ``person in room``); rooms sharing a door are ``adjacent``; stairs and the
elevator are nodes that ``connects`` the corridors of the floors they serve.
"""

from __future__ import annotations

from collections.abc import Callable

from gsr.benchmarks.delivery.building.model import Building, Place

from gsr.scene_graph import BoundingBox, Edge, Keypoint, Node, SceneGraph, Vec3

FLOOR_HEIGHT = 3.0  # metres between floor levels, for the z coordinate of graph geometry


def point_of_place(place: Place, cell_size: float) -> Vec3:
    """World point (metres) of a cell's centre: x along columns, y along rows, z = floor height."""
    floor, row, col = place
    return Vec3(x=(col + 0.5) * cell_size, y=(row + 0.5) * cell_size, z=floor * FLOOR_HEIGHT)


def place_of_point(point: Vec3, cell_size: float) -> Place:
    """The ``(floor, row, col)`` cell containing a world point (inverse of ``point_of_place``)."""
    return (round(point.z / FLOOR_HEIGHT), int(point.y // cell_size), int(point.x // cell_size))


def _box(level: int, rect: tuple[int, int, int, int], cell: float, height: float) -> BoundingBox:
    r0, c0, r1, c1 = rect
    z = level * FLOOR_HEIGHT
    return BoundingBox(
        min=Vec3(x=c0 * cell, y=r0 * cell, z=z), max=Vec3(x=c1 * cell, y=r1 * cell, z=z + height)
    )


def floor_node_id(level: int) -> str:
    """Scene-graph id of a floor node."""
    return f"floor_{level}"


def building_graph(
    building: Building,
    *,
    items: bool = True,
    people_rooms: dict[str, str] | None = None,
    room_of_place: Callable[[tuple[int, int, int]], str | None] | None = None,
) -> SceneGraph:
    """The building's scene graph; ``items=False`` leaves objects out (what a robot knows a priori).

    ``people_rooms`` maps person id -> room id for people to include (e.g. where they are at some time).
    ``room_of_place`` is used to find the corridor a connector's access cell lies in. Rooms and
    receptacles carry geometry in metres (``bbox``; a receptacle's ``access`` keypoint is the cell the
    robot stands on), with z = floor level x ``FLOOR_HEIGHT``.
    """
    bid = "building"
    nodes = [Node(id=bid, category="building", attributes={"name": building.name, "seed": building.seed})]
    edges: list[Edge] = []
    for f in building.floors:
        fid = floor_node_id(f.level)
        nodes.append(Node(id=fid, category="floor", attributes={"name": f.name, "level": f.level}))
        edges.append(Edge(source=fid, relation="in", target=bid))
    cell = building.cell_size
    floor_of = {r.id: r.floor for r in building.rooms}
    for r in building.rooms:
        nodes.append(
            Node(
                id=r.id,
                category=r.kind,
                attributes={"name": r.name, "floor": r.floor},
                bbox=_box(r.floor, r.rect, cell, FLOOR_HEIGHT),
            )
        )
        edges.append(Edge(source=r.id, relation="in", target=floor_node_id(r.floor)))
    pairs = {tuple(sorted(d.rooms)) for d in building.doors}
    for a, b in sorted(pairs):
        edges.append(Edge(source=a, relation="adjacent", target=b))
        edges.append(Edge(source=b, relation="adjacent", target=a))
    for rec in building.receptacles:
        nodes.append(
            Node(
                id=rec.id,
                category=rec.category,
                attributes={"name": rec.name, "holds": rec.relation},
                states=("closed",) if rec.closed else (),
                bbox=_box(floor_of[rec.room], rec.rect, cell, 0.8),
                # where the robot stands to reach it: a functional keypoint, like a handle
                keypoints=(
                    Keypoint(name="access", position=point_of_place((floor_of[rec.room], *rec.access), cell)),
                ),
            )
        )
        edges.append(Edge(source=rec.id, relation="in", target=rec.room))
    if items:
        relation = {rec.id: rec.relation for rec in building.receptacles}
        for it in building.items:
            nodes.append(
                Node(id=it.id, category=it.category, attributes={"name": it.name, "color": it.color})
            )
            edges.append(Edge(source=it.id, relation=relation[it.receptacle], target=it.receptacle))
    for con in building.connectors:
        nodes.append(Node(id=con.id, category=con.kind, attributes={"floors": len(con.access)}))
        for level, cell in sorted(con.access.items()):
            target = room_of_place((level, *cell)) if room_of_place else None
            edges.append(Edge(source=con.id, relation="connects", target=target or floor_node_id(level)))
    for pid, room in sorted((people_rooms or {}).items()):
        p = building.person(pid)
        a = p.appearance
        attrs: dict[str, str | float | int | bool] = {
            "name": p.name,
            "role": p.role,
            "gender": a.gender,
            "garment": a.garment,
            "color": a.color,
            "hair": a.hair,
            "glasses": a.glasses,
        }
        nodes.append(Node(id=pid, category="person", attributes=attrs))
        edges.append(Edge(source=pid, relation="in", target=room))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges), metadata={"building": building.name})
