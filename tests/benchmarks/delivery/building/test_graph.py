"""The building as a hierarchical SceneGraph."""

from __future__ import annotations

from gsr.benchmarks.delivery.building.graph import building_graph
from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap

from gsr.scene_graph import SceneGraph


def test_hierarchy(shipped: Building) -> None:
    bmap = BuildingMap(shipped)
    g = building_graph(
        shipped, people_rooms={p.id: p.home_room for p in shipped.people}, room_of_place=bmap.room_at
    )
    support = {e.source: (e.relation, e.target) for e in g.edges if e.relation in ("in", "on")}
    for f in shipped.floors:
        assert support[f"floor_{f.level}"] == ("in", "building")
    for r in shipped.rooms:
        assert support[r.id] == ("in", f"floor_{r.floor}")
    for rec in shipped.receptacles:
        assert support[rec.id] == ("in", rec.room)
    for it in shipped.items:
        assert support[it.id] == (shipped.receptacle(it.receptacle).relation, it.receptacle)
    for p in shipped.people:
        assert support[p.id] == ("in", p.home_room)
    connects = {(e.source, e.target) for e in g.edges if e.relation == "connects"}
    assert {("elevator", f"corridor_{f.level}") for f in shipped.floors} <= connects
    adjacent = {(e.source, e.target) for e in g.edges if e.relation == "adjacent"}
    for r in shipped.rooms:
        if r.kind != "corridor":
            assert (r.id, f"corridor_{r.floor}") in adjacent
    assert SceneGraph.from_json(g.to_json()) == g


def test_map_only_graph_has_no_objects(shipped: Building) -> None:
    g = building_graph(shipped, items=False)
    ids = {n.id for n in g.nodes}
    assert not ids & {it.id for it in shipped.items}
    assert {rec.id for rec in shipped.receptacles} <= ids


def test_geometry_round_trips_to_grid_places(shipped: Building) -> None:
    from gsr.benchmarks.delivery.building.graph import place_of_point, point_of_place

    g = building_graph(shipped, items=False)
    nodes = g.node_map()
    for rec in shipped.receptacles:
        floor = shipped.room(rec.room).floor
        (kp,) = nodes[rec.id].keypoints
        assert kp.name == "access"
        assert place_of_point(kp.position, shipped.cell_size) == (floor, *rec.access)
        box = nodes[rec.id].bbox
        assert box.min.x == rec.rect[1] * shipped.cell_size and box.max.y == rec.rect[2] * shipped.cell_size
    for room in shipped.rooms:
        box = nodes[room.id].bbox
        r0, c0, r1, c1 = room.rect
        assert place_of_point(box.min, shipped.cell_size) == (room.floor, r0, c0)
        assert (box.max.x - box.min.x, box.max.y - box.min.y) == (
            (c1 - c0) * shipped.cell_size,
            (r1 - r0) * shipped.cell_size,
        )
    assert place_of_point(point_of_place((2, 7, 9), 0.5), 0.5) == (2, 7, 9)
