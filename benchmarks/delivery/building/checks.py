"""Invariants a usable building satisfies: every room reachable, every receptacle reachable, and so on."""

from __future__ import annotations

import numpy as np
from gsr.benchmarks.delivery.building.catalog import OBJECTS, RECEPTACLES, ROLES, ROOM_KINDS
from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap, reachable_cells


def building_problems(building: Building) -> list[str]:
    """Every violated invariant as a one-line message (empty list: the building is sound)."""
    problems: list[str] = []
    bmap = BuildingMap(building)
    elevator = next((c for c in building.connectors if c.kind == "elevator"), None)
    if len(building.floors) > 1 and elevator is None:
        problems.append("a multi-floor building needs an elevator")
    for f in building.floors:
        walk = bmap.walkable[f.level]
        free = np.argwhere(walk)
        if len(free) == 0:
            problems.append(f"floor {f.level}: no walkable cell")
            continue
        start = tuple(
            int(x) for x in (elevator.access[f.level] if elevator and f.level in elevator.access else free[0])
        )
        seen = reachable_cells(walk, start)
        cut = int(walk.sum() - seen.sum())
        if cut:
            problems.append(f"floor {f.level}: {cut} walkable cells cannot be reached from the elevator")
        for con in building.connectors:
            cell = con.access.get(f.level)
            if cell is not None and not walk[cell]:
                problems.append(f"{con.id}: access cell {cell} on floor {f.level} is not walkable")
    for r in building.rooms:
        if r.kind not in ROOM_KINDS:
            problems.append(f"room {r.id}: unknown kind {r.kind!r}")
        if not bmap.free_cells(r.id):
            problems.append(f"room {r.id}: no free cell")
    for rec in building.receptacles:
        room = building.room(rec.room)
        if rec.category not in RECEPTACLES:
            problems.append(f"receptacle {rec.id}: unknown category {rec.category!r}")
        if not room.contains(*rec.access) or not bmap.is_walkable((room.floor, *rec.access)):
            problems.append(f"receptacle {rec.id}: access cell {rec.access} is not a free cell of {room.id}")
        a0, b0, a1, b1 = rec.rect
        grid = building.floor(room.floor).grid
        if any(grid[r][c] != "f" for r in range(a0, a1) for c in range(b0, b1)):
            problems.append(f"receptacle {rec.id}: footprint {rec.rect} is not furniture on the grid")
        if (
            abs(rec.access[0] - min(max(rec.access[0], a0), a1 - 1))
            + abs(rec.access[1] - min(max(rec.access[1], b0), b1 - 1))
            != 1
        ):
            problems.append(f"receptacle {rec.id}: access cell {rec.access} does not touch its footprint")
    for it in building.items:
        if it.category not in OBJECTS:
            problems.append(f"item {it.id}: unknown category {it.category!r}")
    for p in building.people:
        if p.role not in ROLES:
            problems.append(f"person {p.id}: unknown role {p.role!r}")
    for d in building.doors:
        if not bmap.is_walkable((d.floor, *d.cell)):
            problems.append(f"door at {d.cell} on floor {d.floor} is not walkable")
    return problems
