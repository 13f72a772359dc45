"""Floor layouts for generated buildings: a double-loaded corridor with rooms on both sides.

Every floor has the same footprint so the stairs (west end of the corridor) and the elevator (east end)
line up across floors. Rooms are rectangles separated by one-cell walls; each opens onto the corridor
through a two-cell door, and some neighbours share an inner door.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from gsr.benchmarks.delivery.building.catalog import ROOM_KINDS

CORRIDOR_ROWS = 4
CONNECTOR_COLS = 3  # stairs / elevator shafts at the corridor ends


@dataclass
class FloorPlan:
    """A floor being built: a mutable char grid plus its rooms and doors."""

    level: int
    grid: np.ndarray  # dtype '<U1'
    rooms: list[dict] = field(default_factory=list)  # {id, kind, name, rect}
    doors: list[dict] = field(default_factory=list)  # {cell, rooms}
    corridor_id: str = ""
    stairs_access: tuple[int, int] = (0, 0)
    elevator_access: tuple[int, int] = (0, 0)


def _split(total: int, parts: int, minimum: int, rng: np.random.Generator) -> list[int]:
    """Random widths >= minimum summing to ``total`` (one wall cell between parts already removed)."""
    if parts * minimum > total:
        raise ValueError(f"cannot fit {parts} rooms of width >= {minimum} into {total} cells")
    extra = rng.multinomial(total - parts * minimum, np.ones(parts) / parts)
    return [minimum + int(e) for e in extra]


FLOOR_NAMES = ("ground floor", "first floor", "second floor", "third floor", "fourth floor", "fifth floor")


def floor_name(level: int) -> str:
    """'ground floor', 'first floor', ..."""
    return FLOOR_NAMES[level] if level < len(FLOOR_NAMES) else f"floor {level}"


def plan_floor(
    level: int,
    kinds: list[str],
    width: int,
    depth: int,
    rng: np.random.Generator,
    names: dict[str, str],
) -> FloorPlan:
    """Lay out one floor: ``kinds`` (even count) split between the north and south side of the corridor."""
    per_side = len(kinds) // 2
    height = 1 + depth + 1 + CORRIDOR_ROWS + 1 + depth + 1
    grid = np.full((height, width), "#", dtype="<U1")
    c_top = 1 + depth + 1  # first corridor row
    grid[c_top : c_top + CORRIDOR_ROWS, 1 : width - 1] = "."
    grid[c_top : c_top + CORRIDOR_ROWS, 1 : 1 + CONNECTOR_COLS] = "S"
    grid[c_top : c_top + CORRIDOR_ROWS, width - 1 - CONNECTOR_COLS : width - 1] = "E"
    mid = c_top + CORRIDOR_ROWS // 2
    plan = FloorPlan(level, grid)
    plan.stairs_access = (mid, 1 + CONNECTOR_COLS)
    plan.elevator_access = (mid, width - 2 - CONNECTOR_COLS)
    plan.corridor_id = f"corridor_{level}"
    plan.rooms.append(
        {
            "id": plan.corridor_id,
            "kind": "corridor",
            "name": f"{floor_name(level)} corridor",
            "rect": (c_top, 1, c_top + CORRIDOR_ROWS, width - 1),
        }
    )
    number = 100 * (level + 1)
    for side, (r0, r1, door_row) in enumerate(
        (
            (1, 1 + depth, c_top - 1),
            (c_top + CORRIDOR_ROWS + 1, c_top + CORRIDOR_ROWS + 1 + depth, c_top + CORRIDOR_ROWS),
        )
    ):
        side_kinds = kinds[side * per_side : (side + 1) * per_side]
        widths = _split(width - 2 - (per_side - 1), per_side, 10, rng)
        c0 = 1
        prev: dict | None = None
        for kind, w in zip(side_kinds, widths, strict=True):
            number += 1
            rid = f"{kind}_{number}"
            label = names.get(kind) or f"{ROOM_KINDS[kind].name} {number}"
            room = {"id": rid, "kind": kind, "name": label, "rect": (r0, c0, r1, c0 + w)}
            grid[r0:r1, c0 : c0 + w] = "."
            # corridor door: two cells wide, clear of the connector shafts and the room's corners
            lo = max(c0 + 1, 2 + CONNECTOR_COLS)
            hi = min(c0 + w - 3, width - 4 - CONNECTOR_COLS)
            dc = int(rng.integers(lo, hi + 1))
            for c in (dc, dc + 1):
                grid[door_row, c] = "d"
                plan.doors.append({"cell": (door_row, c), "rooms": (rid, plan.corridor_id)})
            if prev is not None and rng.random() < 0.35:
                # an inner door through the shared wall column
                dr = int(rng.integers(r0 + 1, r1 - 2))
                for r in (dr, dr + 1):
                    grid[r, c0 - 1] = "d"
                    plan.doors.append({"cell": (r, c0 - 1), "rooms": (prev["id"], rid)})
            plan.rooms.append(room)
            prev = room
            c0 += w + 1
    return plan
