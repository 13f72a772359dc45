"""Furnishing generated rooms: receptacles along the walls, objects on and in them.

Placement keeps every room navigable: a receptacle never touches a door, never sits on another's access
cell, keeps a one-cell ring free towards the room, and the room's free cells stay one connected region.
"""

from __future__ import annotations

import numpy as np
from gsr.benchmarks.delivery.building.catalog import OBJECTS, RECEPTACLES, ROOM_KINDS
from gsr.benchmarks.delivery.building.navigation import reachable_cells


def _connected(free: np.ndarray) -> bool:
    """True when the True cells of ``free`` form one 4-connected region."""
    cells = np.argwhere(free)
    if len(cells) == 0:
        return False
    return int(reachable_cells(free, tuple(cells[0])).sum()) == len(cells)


def place_receptacles(
    grid: np.ndarray, room: dict, rng: np.random.Generator, reserved: set[tuple[int, int]]
) -> list[dict]:
    """Put the room kind's receptacles against the walls; returns ``{id, category, rect, access}`` dicts."""
    kind = ROOM_KINDS[room["kind"]]
    wanted = list(kind.receptacles[: kind.always])
    wanted += [c for c in kind.receptacles[kind.always :] if rng.random() < 0.7]
    r0, c0, r1, c1 = room["rect"]
    out: list[dict] = []
    for category in wanted:
        rt = RECEPTACLES[category]
        placed = _place_one(grid, (r0, c0, r1, c1), rt.size, rng, reserved)
        if placed is None:
            continue  # room too full: skip this optional piece
        rect, access = placed
        out.append({"category": category, "rect": rect, "access": access})
    return out


Rect = tuple[int, int, int, int]


def _place_one(
    grid: np.ndarray,
    bounds: Rect,
    size: tuple[int, int],
    rng: np.random.Generator,
    reserved: set[tuple[int, int]],
) -> tuple[Rect, tuple[int, int]] | None:
    """Footprint and access cell for one piece against a wall of ``bounds`` (None if it cannot fit)."""
    r0, c0, r1, c1 = bounds
    candidates = []
    for h, w in {size, size[::-1]}:
        for r in range(r0, r1 - h + 1):
            for c in range(c0, c1 - w + 1):
                touches_wall = r == r0 or c == c0 or r + h == r1 or c + w == c1
                if touches_wall:
                    candidates.append((r, c, h, w))
    order = rng.permutation(len(candidates))
    for i in order:
        r, c, h, w = candidates[int(i)]
        if not _fits(grid, (r, c, r + h, c + w), reserved):
            continue
        trial = grid.copy()
        trial[r : r + h, c : c + w] = "f"
        room_free = np.isin(trial[r0:r1, c0:c1], [".", "d"])
        if not _connected(room_free):
            continue
        access = _access_cell(trial, bounds, (r, c, r + h, c + w), reserved)
        if access is None:
            continue
        grid[r : r + h, c : c + w] = "f"
        reserved.add(access)
        return (r, c, r + h, c + w), access
    return None


def _fits(grid: np.ndarray, rect: Rect, reserved: set[tuple[int, int]]) -> bool:
    a0, b0, a1, b1 = rect
    # the footprint must be free floor (and no reserved access cell); its one-cell ring holds no
    # furniture or door, so pieces never touch and a passage always remains around them
    for r in range(a0 - 1, a1 + 1):
        for c in range(b0 - 1, b1 + 1):
            ch = grid[r, c]
            if a0 <= r < a1 and b0 <= c < b1:
                if ch != "." or (r, c) in reserved:
                    return False
            elif ch in ("f", "d"):
                return False
    # no door directly in front of the piece (two cells away), so doorways stay open
    for r in range(max(a0 - 2, 0), min(a1 + 2, grid.shape[0])):
        for c in range(max(b0 - 2, 0), min(b1 + 2, grid.shape[1])):
            if grid[r, c] == "d":
                return False
    return True


def _access_cell(
    grid: np.ndarray, bounds: Rect, rect: Rect, reserved: set[tuple[int, int]]
) -> tuple[int, int] | None:
    """The free in-room cell next to the piece that is closest to the room centre."""
    r0, c0, r1, c1 = bounds
    a0, b0, a1, b1 = rect
    centre = ((r0 + r1) / 2, (c0 + c1) / 2)
    best = None
    for r in range(a0 - 1, a1 + 1):
        for c in range(b0 - 1, b1 + 1):
            on_side = (a0 <= r < a1) != (b0 <= c < b1)  # edge-adjacent, not a corner
            if not on_side or not (r0 <= r < r1 and c0 <= c < c1):
                continue
            if grid[r, c] != "." or (r, c) in reserved:
                continue
            d = (r - centre[0]) ** 2 + (c - centre[1]) ** 2
            if best is None or d < best[0]:
                best = (d, (r, c))
    return best[1] if best else None


def stock_items(
    receptacles: list[dict], room_kind: str, rng: np.random.Generator, counts: dict[str, int]
) -> list[dict]:
    """Objects for one room's receptacles: 1-3 each, of types that live in this kind of room."""
    types = [o for o in OBJECTS.values() if room_kind in o.rooms]
    items: list[dict] = []
    if not types:
        return items
    for rec in receptacles:
        for _ in range(int(rng.integers(1, 4))):
            ot = types[int(rng.integers(len(types)))]
            color = ot.colors[int(rng.integers(len(ot.colors)))]
            counts[ot.category] = counts.get(ot.category, 0) + 1
            items.append(
                {
                    "id": f"{ot.category}_{counts[ot.category]}",
                    "category": ot.category,
                    "name": ot.name,
                    "color": color,
                    "receptacle": rec["id"],
                }
            )
    return items
