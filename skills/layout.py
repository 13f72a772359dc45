"""Layouts for tasks that come without one: fixtures at the back, objects sampled in reach (seeded).

A TaskSpec's ``layout`` is authoritative when present; :func:`layout_from_graph` builds one from the
initial scene graph otherwise (LIBERO tasks from BDDL, hand-written graphs). The table is centred on
the world origin; the world puts the robot's rail in front of the nearest object.
"""

from __future__ import annotations

import random

from gsr.skills.assets import asset_category, make_asset

from gsr.categories import is_a
from gsr.scene_graph import SceneGraph
from gsr.task_spec import Layout, PlacedObject, Region

#: Fixture slots (x, y, yaw) on a 0.9 x 1.2 table: back row, then the back corners.
FIXTURE_SLOTS: tuple[tuple[float, float], ...] = (
    (0.2, -0.4),
    (0.2, 0.4),
    (0.24, 0.0),
    (-0.05, -0.45),
    (-0.05, 0.45),
)
TABLE = (0.9, 1.2)
#: Where movable objects are sampled (x range, y range), in front of the fixtures.
FREE_X, FREE_Y = (-0.25, -0.03), (-0.35, 0.35)


def _fixture_spot(
    extent: tuple[float, float, float], slot: int, rects: list[tuple[float, float, float, float]]
) -> tuple[float, float]:
    """The first slot (from ``slot`` on, then shifted sideways by up to 15 cm) where a fixture of this
    extent stays on the table and 2 cm clear of the fixtures already placed; else slot ``slot`` itself.

    Fixtures overlapping each other would interpenetrate, and a door hinged inside a neighbour is
    pushed open by the contact solver.
    """
    hx, hy = extent[0] / 2, extent[1] / 2
    order = [FIXTURE_SLOTS[(slot + k) % len(FIXTURE_SLOTS)] for k in range(len(FIXTURE_SLOTS))]
    for x0, y0 in order:
        for dy in (0.0, -0.05, 0.05, -0.1, 0.1, -0.15, 0.15):
            x, y = x0, y0 + dy
            inside = abs(x) + hx <= TABLE[0] / 2 and abs(y) + hy <= TABLE[1] / 2
            if inside and all(
                abs(x - rx) >= hx + rhx + 0.02 or abs(y - ry) >= hy + rhy + 0.02 for rx, ry, rhx, rhy in rects
            ):
                return x, y
    return order[0]


def _is_fixture(graph: SceneGraph, node_id: str) -> bool:
    n = graph.node(node_id)
    if n.attributes.get("fixture") is True or n.attributes.get("movable") is False:
        return True
    return make_asset(str(n.attributes.get("asset") or n.category)).fixed


def layout_from_graph(graph: SceneGraph, seed: int = 0) -> Layout:
    """A deterministic layout for a graph: fixtures in slots, objects in free spots, stacks from on/in edges."""
    rng = random.Random(seed)
    support = {k: (e.relation, e.target) for k, e in graph.supports().items()}
    tables = {n.id for n in graph.nodes if n.parent is None and is_a(n.category, "table")}
    roots = [
        n for n in graph.nodes if n.parent is None and n.id not in tables and not is_a(n.category, "floor")
    ]
    placed: list[PlacedObject] = []
    footprints: list[tuple[float, float, float]] = []  # x, y, radius
    slot = 0
    rects: list[tuple[float, float, float, float]] = []  # fixtures placed so far: x, y, half sizes
    regions: list[Region] = []
    for n in roots:
        if not _is_fixture(graph, n.id) or (n.id in support and support[n.id][1] not in tables):
            continue
        asset = str(n.attributes.get("asset") or n.category)
        model = make_asset(asset)
        x, y = _fixture_spot(model.extent, slot, rects)
        slot += 1
        rects.append((x, y, model.extent[0] / 2, model.extent[1] / 2))
        placed.append(PlacedObject(id=n.id, asset=asset, position=(x, y, 0.0), fixed=True, color=n.color))
        footprints.append((x, y, max(model.extent[:2]) / 2 + 0.03))
        if any(a.kind in ("drawer", "door") for a in model.articulations.values()):
            # keep the space drawers and doors swing into free (they open towards the robot, -x)
            footprints.append((x - model.extent[0] / 2 - 0.12, y, 0.16))
    # named table regions (LIBERO "stove_front_region"): a rectangle in front of the named fixture, else free
    for n in graph.nodes:
        if n.parent in tables and is_a(n.category, "region"):
            words = n.id.split("/")[-1]
            anchor = next((p for p in placed if graph.node(p.id).category in words), None)
            if anchor is not None:
                x, y = anchor.position[0] - 0.26, anchor.position[1]
            else:
                x, y = _free_spot(rng, footprints, 0.1)
            regions.append(
                Region(name=n.id, target=n.parent or "table", bounds=(x - 0.09, y - 0.11, x + 0.09, y + 0.11))
            )
            footprints.append((x, y, 0.13))
    pending = [n for n in roots if not any(p.id == n.id for p in placed)]
    # objects on the table first, then what rests on or in them (in dependency order)
    done = {p.id for p in placed} | tables
    for _ in range(len(pending) + 1):
        for n in list(pending):
            _rel, target = support.get(n.id, ("on", next(iter(tables), "table")))
            base = target.split("/")[0]
            if target not in tables and base not in done and not any(r.name == target for r in regions):
                continue
            pending.remove(n)
            done.add(n.id)
            asset = str(n.attributes.get("asset") or n.category)
            model = make_asset(asset)
            radius = max(model.extent[:2]) / 2 + 0.02
            region = next((r for r in regions if r.name == target), None)
            if region is not None:
                x, y = (region.bounds[0] + region.bounds[2]) / 2, (region.bounds[1] + region.bounds[3]) / 2
                on = None
            elif target in tables:
                x, y = _free_spot(rng, footprints, radius)
                footprints.append((x, y, radius))
                on = None
            else:
                # on or in another object or a part (drawer, compartment): the world puts it at the
                # host's interior or top when it builds the scene
                host = next(p for p in placed if p.id == base)
                x, y = host.position[0], host.position[1]
                on = target
            placed.append(
                PlacedObject(
                    id=n.id,
                    asset=asset,
                    position=(round(x, 4), round(y, 4), 0.0),
                    on=on,
                    color=n.color,
                    yaw=0.0,
                )
            )
    return Layout(objects=tuple(placed), regions=tuple(regions), table_size=TABLE, seed=seed)


def _free_spot(
    rng: random.Random, footprints: list[tuple[float, float, float]], radius: float
) -> tuple[float, float]:
    best, best_gap = (0.0, 0.0), -1.0
    for _ in range(200):  # rejection sampling; keep the roomiest candidate if none is fully free
        x, y = rng.uniform(*FREE_X), rng.uniform(*FREE_Y)
        gap = min(
            (((x - fx) ** 2 + (y - fy) ** 2) ** 0.5 - fr - radius for fx, fy, fr in footprints), default=1.0
        )
        if gap > 0.04:  # room for the fingers on either side
            return x, y
        if gap > best_gap:
            best, best_gap = (x, y), gap
    return best


def asset_kind(asset: str) -> str:
    """The procedural builder an asset name resolves to (re-exported for callers of layouts)."""
    return asset_category(asset)
