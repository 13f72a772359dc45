"""The building as a hierarchical SceneGraph."""

from __future__ import annotations

from gsr.building.graph import building_graph
from gsr.building.model import Building
from gsr.building.navigation import BuildingMap
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
