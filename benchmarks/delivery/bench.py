"""Speed of the delivery stack: A* queries, people lookups, whole episodes (simulated vs real time).

Run: ``.venv/bin/python -m gsr.benchmarks.delivery.bench [--episodes 200]``. Prints a Markdown table.
Times are CPU seconds of this process (``time.process_time``), so a busy machine does not skew them.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from gsr.benchmarks.delivery.building.navigation import BuildingMap, astar
from gsr.benchmarks.delivery.building.people import PeopleClock
from gsr.benchmarks.delivery.building.shipped import load_shipped_building
from gsr.benchmarks.delivery.run import run_split


def bench(episodes: int = 200, pairs: int = 2000, seed: int = 0) -> list[tuple[str, str]]:
    """Rows (workload, figure) measured on the shipped building."""
    b = load_shipped_building()
    bmap = BuildingMap(b)
    rng = np.random.default_rng(seed)
    rows = []
    grid = bmap.walkable[0]
    cells = [tuple(int(x) for x in rc) for rc in np.argwhere(grid)]
    picks = [
        (cells[int(rng.integers(len(cells)))], cells[int(rng.integers(len(cells)))]) for _ in range(pairs)
    ]
    t = time.process_time()
    total = 0
    for a, g in picks:
        path = astar(grid, a, g)
        total += len(path or ())
    dt = time.process_time() - t
    rows.append(("A* on a 76x30 floor grid, random cell pairs", f"{dt / pairs * 1e3:.2f} ms/query"))
    clock = PeopleClock(b, 1, bmap)
    times = rng.uniform(8 * 3600, 20 * 3600, size=5000)
    t = time.process_time()
    for x in times:
        clock.people_in(b.rooms[0].id, float(x))
    dt = time.process_time() - t
    rows.append(
        ("who is in a room at time t (12 people, incl. walks)", f"{dt / len(times) * 1e6:.0f} µs/query")
    )
    t = time.process_time()
    out = run_split(b, "test", episodes)
    dt = time.process_time() - t
    sim = sum(r.time for r in out.results)
    rows.append((f"baseline episodes (first {episodes} test tasks)", f"{dt / episodes * 1e3:.1f} ms/episode"))
    rows.append(("simulated seconds per CPU second", f"{sim / dt:,.0f}"))
    return rows


def main() -> None:
    """CLI entry: print the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--pairs", type=int, default=2000)
    args = ap.parse_args()
    print("| workload | figure |\n|---|---:|")
    for name, fig in bench(args.episodes, args.pairs):
        print(f"| {name} | {fig} |")


if __name__ == "__main__":
    main()
