"""The shipped three-floor building: reproducible from its command, and meeting the issue's numbers."""

from __future__ import annotations

from collections import Counter

import numpy as np
from gsr.benchmarks.delivery.building.checks import building_problems
from gsr.benchmarks.delivery.building.generator import generate_building
from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.shipped import SHIPPED_NAME, SHIPPED_SEED, shipped_building_path


def test_regenerates_byte_for_byte() -> None:
    text = shipped_building_path().read_text(encoding="utf-8")
    assert generate_building(SHIPPED_SEED, name=SHIPPED_NAME).to_json() + "\n" == text


def test_sizes_and_contents(shipped: Building) -> None:
    assert [f.level for f in shipped.floors] == [0, 1, 2]
    rooms = [r for r in shipped.rooms if r.kind != "corridor"]
    assert len(rooms) >= 20
    kinds = Counter(r.kind for r in rooms)
    for kind in (
        "bedroom",
        "office",
        "laboratory",
        "medical_room",
        "kitchen",
        "gym",
        "living_room",
        "leisure_room",
    ):
        assert kinds[kind] >= 1, kind
    assert kinds["bedroom"] >= 2 and kinds["office"] >= 2
    assert len({it.category for it in shipped.items}) >= 40
    assert len(shipped.people) >= 10
    assert {c.kind for c in shipped.connectors} == {"stairs", "elevator"}
    for r in rooms:
        assert any(rec.room == r.id for rec in shipped.receptacles), f"{r.id} has no receptacle"


def test_invariants(shipped: Building) -> None:
    assert building_problems(shipped) == []


def test_every_receptacle_reachable_from_the_lobby(shipped: Building) -> None:
    bmap = BuildingMap(shipped)
    lobby = next(r for r in shipped.rooms if r.kind == "lobby")
    start = (lobby.floor, *bmap.free_cells(lobby.id)[0])
    for rec in shipped.receptacles:
        floor = shipped.room(rec.room).floor
        route = bmap.route(start, (floor, *rec.access))
        assert route is not None, rec.id
        assert route.seconds(1.0) < 240, rec.id  # any receptacle is well within the 8-minute limit


def test_grid_rooms_match_rects(shipped: Building) -> None:
    for room in shipped.rooms:
        grid = np.array([list(row) for row in shipped.floor(room.floor).grid])
        r0, c0, r1, c1 = room.rect
        inner = grid[r0:r1, c0:c1]
        assert not (inner == "#").any(), f"{room.id}: wall inside the room rect"
