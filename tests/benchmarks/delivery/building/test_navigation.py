"""A* against brute force on small grids, and routes between floors."""

from __future__ import annotations

import heapq
import itertools
import math
from collections import deque

import numpy as np
import pytest
from gsr.benchmarks.delivery.building.navigation import (
    BuildingMap,
    astar,
    connector_seconds,
    path_cells_length,
)


def _bfs(free: np.ndarray, start, goal):
    """Brute-force 4-connected shortest path length (None if unreachable)."""
    dist = {start: 0}
    q = deque([start])
    while q:
        cur = q.popleft()
        if cur == goal:
            return dist[cur]
        r, c = cur
        for n in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if 0 <= n[0] < free.shape[0] and 0 <= n[1] < free.shape[1] and free[n] and n not in dist:
                dist[n] = dist[cur] + 1
                q.append(n)
    return None


def _dijkstra8(free: np.ndarray, start, goal):
    """Brute-force 8-connected (no corner cutting) shortest path length."""
    best = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if (r, c) == goal:
            return d
        if d > best[(r, c)]:
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if not (dr or dc):
                    continue
                n = (r + dr, c + dc)
                if not (0 <= n[0] < free.shape[0] and 0 <= n[1] < free.shape[1]) or not free[n]:
                    continue
                if dr and dc and not (free[r, c + dc] and free[r + dr, c]):
                    continue
                nd = d + (math.sqrt(2) if dr and dc else 1.0)
                if nd < best.get(n, math.inf):
                    best[n] = nd
                    heapq.heappush(heap, (nd, n))
    return None


def _check_path(free, path, start, goal, diagonal):
    assert path[0] == start and path[-1] == goal
    for a, b in itertools.pairwise(path):
        assert free[b]
        dr, dc = abs(a[0] - b[0]), abs(a[1] - b[1])
        assert max(dr, dc) == 1 and (diagonal or dr + dc == 1)


@pytest.mark.parametrize("seed", range(40))
def test_astar_matches_brute_force(seed: int) -> None:
    rng = np.random.default_rng(seed)
    shape = (int(rng.integers(3, 12)), int(rng.integers(3, 12)))
    free = rng.random(shape) > rng.uniform(0.1, 0.45)
    cells = [tuple(int(x) for x in rc) for rc in np.argwhere(free)]
    if len(cells) < 2:
        pytest.skip("degenerate grid")
    for _ in range(8):
        s = cells[int(rng.integers(len(cells)))]
        g = cells[int(rng.integers(len(cells)))]
        p4 = astar(free, s, g, diagonal=False)
        ref4 = _bfs(free, s, g)
        assert (p4 is None) == (ref4 is None)
        if p4 is not None:
            assert len(p4) - 1 == ref4
            _check_path(free, p4, s, g, diagonal=False)
        p8 = astar(free, s, g)
        ref8 = _dijkstra8(free, s, g)
        assert (p8 is None) == (ref8 is None)
        if p8 is not None:
            assert path_cells_length(p8) == pytest.approx(ref8)
            _check_path(free, p8, s, g, diagonal=True)


def test_astar_rejects_blocked_endpoints() -> None:
    free = np.ones((3, 3), dtype=bool)
    free[1, 1] = False
    with pytest.raises(ValueError, match="start cell"):
        astar(free, (1, 1), (0, 0))
    with pytest.raises(ValueError, match="goal cell"):
        astar(free, (0, 0), (5, 5))
    assert astar(free, (0, 0), (0, 0)) == [(0, 0)]


def test_no_corner_cutting() -> None:
    free = np.array([[True, False], [False, True]])
    assert astar(free, (0, 0), (1, 1)) is None


def test_routes_between_floors_use_the_elevator(shipped) -> None:
    bmap = BuildingMap(shipped)
    elevator = next(c for c in shipped.connectors if c.kind == "elevator")
    a = (0, *elevator.access[0])
    b = (2, *elevator.access[2])
    route = bmap.route(a, b)
    assert route is not None and route.connector == "elevator"
    assert route.metres == 0
    assert route.connector_seconds == pytest.approx(connector_seconds(elevator, 0, 2))
    assert route.connector_seconds == pytest.approx(20 + 2 * 6 + 2 * 4)
    stairs_ok = bmap.route(a, b, allow_stairs=True)
    assert stairs_ok is not None and stairs_ok.seconds(1.0) <= route.seconds(1.0)
    # travel time scales with speed only in its walking part
    lobby = next(r for r in shipped.rooms if r.kind == "lobby")
    cell = bmap.free_cells(lobby.id)[0]
    r2 = bmap.route((lobby.floor, *cell), b)
    assert r2.seconds(0.5) - r2.seconds(1.0) == pytest.approx(r2.metres)


def test_distance_is_geodesic(shipped) -> None:
    bmap = BuildingMap(shipped)
    room = next(r for r in shipped.rooms if r.kind == "kitchen")
    cells = bmap.free_cells(room.id)
    a, b = (room.floor, *cells[0]), (room.floor, *cells[-1])
    assert bmap.distance(a, b) >= bmap.euclidean(a, b) - 1e-9
    assert bmap.distance(a, (room.floor + 1, *cells[0])) == math.inf
