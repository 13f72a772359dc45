"""Navigation in a building: A* on each floor's occupancy grid, stairs/elevator between floors, travel time.

``BuildingMap`` indexes a ``Building`` once (numpy grids, room membership) and answers path and route
queries. Within a floor the robot moves 8-connected (diagonal steps cost sqrt 2 cells and may not cut
wall corners); between floors it rides the elevator (and, if allowed, takes the stairs).
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections import deque
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from gsr.benchmarks.delivery.building.model import WALKABLE, Building, Cell, Connector, Place

_SQRT2 = math.sqrt(2.0)
_STEPS_8 = (
    (-1, 0, 1.0),
    (1, 0, 1.0),
    (0, -1, 1.0),
    (0, 1, 1.0),
    (-1, -1, _SQRT2),
    (-1, 1, _SQRT2),
    (1, -1, _SQRT2),
    (1, 1, _SQRT2),
)


def reachable_cells(walkable: np.ndarray, start: Cell) -> np.ndarray:
    """Boolean grid of the cells 4-connected to ``start`` through True cells of ``walkable`` (all False
    when ``start`` itself is not walkable)."""
    seen = np.zeros(walkable.shape, dtype=bool)
    if not walkable[start]:
        return seen
    seen[start] = True
    queue = deque([start])
    rows, cols = walkable.shape
    while queue:
        r, c = queue.popleft()
        for nr, nc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= nr < rows and 0 <= nc < cols and walkable[nr, nc] and not seen[nr, nc]:
                seen[nr, nc] = True
                queue.append((nr, nc))
    return seen


def astar(walkable: np.ndarray, start: Cell, goal: Cell, diagonal: bool = True) -> list[Cell] | None:
    """Shortest path of cells from ``start`` to ``goal`` on a boolean grid (None if unreachable).

    With ``diagonal`` the moves are 8-connected (no corner cutting) and the heuristic is the octile
    distance; without, 4-connected with the Manhattan distance. Both heuristics are consistent, so the
    first time the goal is popped its cost is optimal.
    """
    rows, cols = walkable.shape
    for name, (r, c) in (("start", start), ("goal", goal)):
        if not (0 <= r < rows and 0 <= c < cols) or not walkable[r, c]:
            raise ValueError(f"{name} cell {(r, c)} is not walkable")
    if start == goal:
        return [start]
    free = walkable.ravel().tolist()  # python list: much faster than numpy scalar indexing in the loop
    steps = _STEPS_8 if diagonal else _STEPS_8[:4]
    gr, gc = goal
    s, g = start[0] * cols + start[1], gr * cols + gc
    best = {s: 0.0}
    parent = {s: -1}
    heap = [(0.0, 0.0, s)]
    while heap:
        _, cost, cur = heapq.heappop(heap)
        if cur == g:
            path = []
            while cur != -1:
                path.append(divmod(cur, cols))
                cur = parent[cur]
            return path[::-1]
        if cost > best[cur]:
            continue  # stale heap entry
        r, c = divmod(cur, cols)
        for dr, dc, w in steps:
            nr, nc = r + dr, c + dc
            if not (0 <= nr < rows and 0 <= nc < cols):
                continue
            n = nr * cols + nc
            if not free[n]:
                continue
            if dr and dc and not (free[r * cols + nc] and free[nr * cols + c]):
                continue  # no squeezing diagonally past a wall corner
            nc_cost = cost + w
            if nc_cost < best.get(n, math.inf):
                best[n] = nc_cost
                parent[n] = cur
                ddr, ddc = abs(nr - gr), abs(nc - gc)
                h = (max(ddr, ddc) + (_SQRT2 - 1) * min(ddr, ddc)) if diagonal else float(ddr + ddc)
                heapq.heappush(heap, (nc_cost + h, nc_cost, n))
    return None


def path_cells_length(path: list[Cell]) -> float:
    """Length of a cell path in cells (1 per straight step, sqrt 2 per diagonal one)."""
    return sum(_SQRT2 if (a[0] != b[0] and a[1] != b[1]) else 1.0 for a, b in itertools.pairwise(path))


@dataclass(frozen=True)
class Route:
    """A route between two places: metres walked, connector used, and seconds spent on connectors."""

    metres: float
    connector: str | None
    connector_seconds: float

    def seconds(self, speed: float) -> float:
        """Travel time at ``speed`` metres per second."""
        return self.metres / speed + self.connector_seconds


def connector_seconds(connector: Connector, from_floor: int, to_floor: int) -> float:
    """Time to change floors with a connector (elevator: call wait + ride + doors at both ends)."""
    floors = abs(to_floor - from_floor)
    if connector.kind == "elevator":
        return connector.call_seconds + floors * connector.seconds_per_floor + 2 * connector.door_seconds
    return floors * connector.seconds_per_floor


class BuildingMap:
    """Indexed grids of a building: walkability, room membership, free cells per room, routes."""

    def __init__(self, building: Building) -> None:
        self.building = building
        self.cell_size = building.cell_size
        self.walkable: dict[int, np.ndarray] = {}
        self.room_index: dict[int, np.ndarray] = {}
        self.room_ids: list[str] = [r.id for r in building.rooms]
        for f in building.floors:
            grid = np.array([list(row) for row in f.grid])
            self.walkable[f.level] = np.isin(grid, list(WALKABLE))
            idx = np.full(f.shape, -1, dtype=np.int32)
            self.room_index[f.level] = idx
        for i, r in enumerate(building.rooms):
            r0, c0, r1, c1 = r.rect
            self.room_index[r.floor][r0:r1, c0:c1] = i
        self._free: dict[str, list[Cell]] = {}
        self._path = lru_cache(maxsize=65536)(self._path_uncached)

    # ------------------------------------------------------------ rooms

    def room_at(self, place: Place) -> str | None:
        """The id of the room containing this place (None on a door or wall cell)."""
        f, r, c = place
        i = int(self.room_index[f][r, c])
        return self.room_ids[i] if i >= 0 else None

    def free_cells(self, room_id: str) -> list[Cell]:
        """Walkable cells inside a room, row-major (cached)."""
        if room_id not in self._free:
            room = self.building.room(room_id)
            r0, c0, r1, c1 = room.rect
            sub = self.walkable[room.floor][r0:r1, c0:c1]
            self._free[room_id] = [(int(r) + r0, int(c) + c0) for r, c in np.argwhere(sub)]
        return self._free[room_id]

    def is_walkable(self, place: Place) -> bool:
        """True when a place is inside the building and free."""
        f, r, c = place
        grid = self.walkable.get(f)
        return grid is not None and 0 <= r < grid.shape[0] and 0 <= c < grid.shape[1] and bool(grid[r, c])

    # ------------------------------------------------------------ paths

    def _path_uncached(self, floor: int, start: Cell, goal: Cell) -> tuple[Cell, ...] | None:
        path = astar(self.walkable[floor], start, goal)
        return tuple(path) if path is not None else None

    def path(self, floor: int, start: Cell, goal: Cell) -> tuple[Cell, ...] | None:
        """The A* path between two cells of a floor (cached; None if unreachable)."""
        return self._path(floor, tuple(start), tuple(goal))

    def floor_distance(self, floor: int, start: Cell, goal: Cell) -> float:
        """Walking distance in metres between two cells of one floor (inf if unreachable)."""
        p = self.path(floor, start, goal)
        return math.inf if p is None else path_cells_length(list(p)) * self.cell_size

    def distance(self, a: Place, b: Place) -> float:
        """Walking (geodesic) distance in metres between two places; inf across floors or if cut off."""
        if a[0] != b[0]:
            return math.inf
        return self.floor_distance(a[0], a[1:], b[1:])

    def euclidean(self, a: Place, b: Place) -> float:
        """Straight-line distance in metres on one floor (inf across floors): a lower bound of ``distance``."""
        if a[0] != b[0]:
            return math.inf
        return math.hypot(a[1] - b[1], a[2] - b[2]) * self.cell_size

    def route(self, a: Place, b: Place, allow_stairs: bool = False) -> Route | None:
        """The fastest route between places: walk, or walk + connector + walk (None if unreachable)."""
        if a[0] == b[0]:
            d = self.distance(a, b)
            return None if math.isinf(d) else Route(d, None, 0.0)
        best: Route | None = None
        for con in self.building.connectors:
            if con.kind == "stairs" and not allow_stairs:
                continue
            if a[0] not in con.access or b[0] not in con.access:
                continue
            d1 = self.floor_distance(a[0], a[1:], con.access[a[0]])
            d2 = self.floor_distance(b[0], con.access[b[0]], b[1:])
            if math.isinf(d1) or math.isinf(d2):
                continue
            cand = Route(d1 + d2, con.id, connector_seconds(con, a[0], b[0]))
            # compare at a nominal 1 m/s; the robot's real speed only rescales the walking part
            if best is None or cand.seconds(1.0) < best.seconds(1.0):
                best = cand
        return best
