"""Importer for the public GSR-Bench config file (``3Ddesk/saved_configs.yaml``) into TaskSpecs.

Each config holds the scene graph as GSR-Bench strings (``nodes`` / ``edges``), the object lists with
poses (``boxes``, ``boxes_with_lid``, ``mugs``, ``cubes``, ``libero_assets`` with drawer states) and the
natural-language ``task_query``. The scene graph is authoritative for relations (the benchmark computes
``on``/``in`` from bounding boxes); the object lists give the physical layout.

Units and frame. The benchmark's 3D desk is a three.js/cannon scene in centimetres with +y up; the
camera (and robot) look at the desk from the +z side. Our world frame is metres with +x forward (away
from the robot), +y left, +z up, so a benchmark point (x, y, z) maps to
``(-z / 100, -x / 100, y / 100)`` (a proper rotation), and a benchmark yaw about +y becomes the same
yaw about our +z. Benchmark positions are body centres; ours are base centres, so the desk top (2 cm:
the desk is 4 cm thick, centred at 0) and the primitive's half height are subtracted. The config file
gives no sizes; they are the benchmark's own (``3Ddesk/modular_project/src/objects``: ``Cube.js`` 3 cm,
``Mug.js`` radius 2.2 cm x 5 cm, ``Box.js`` 25 x 17 cm outside, 1 cm walls, 8.5 cm tall, long side along
the benchmark's x = our y). LIBERO assets resting on the table get base height 0, others keep their
centre height (their extents are not in the file).

Node names follow the benchmark's naming (``ObjectNaming.js``): colour index 0/1/2/3/4 = red, yellow,
blue, green, white; the k-th object of a colour in list order is ``<colour>_cube<k>``; boxes are
``<colour>_box``, lidded boxes ``<colour>_lid_box``; LIBERO assets keep their ``assetId``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from gsr.benchmarks.suites.gsr_bench_goals import goal_for_query

from gsr.errors import GSRError
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.scene_graph import SceneGraph
from gsr.task_spec import Layout, PlacedObject, TaskSpec, task_from_dict

COLORS = ("red", "yellow", "blue", "green", "white")
#: Primitive kind -> (asset, size x/y/z in m), from the benchmark's object sources (see above).
PRIMITIVES: dict[str, tuple[str, tuple[float, float, float]]] = {
    "cubes": ("cube", (0.03, 0.03, 0.03)),
    "mugs": ("mug", (0.044, 0.044, 0.05)),
    "boxes": ("box", (0.17, 0.25, 0.085)),
    "boxes_with_lid": ("box_with_lid", (0.17, 0.25, 0.085)),
}
#: LIBERO assets whose size the benchmark's tasks bound (m): the book goes into closed lidded boxes
#: (7.5 cm inside) and the book, milk and popcorn into drawer layers of the short cabinet that are
#: closed afterwards (our drawers are 7.9 cm tall), so these stand at most 6.5 cm tall; the other
#: assets keep our default sizes.
LIBERO_SIZES: dict[str, tuple[float, float, float]] = {
    "yellow_book": (0.03, 0.11, 0.065),
    "milk": (0.05, 0.05, 0.065),
    "popcorn": (0.04, 0.07, 0.065),
}
DESK_TOP = 0.02  # m: the benchmark's desk top above its origin (cube centres rest at y = 3.5 cm)
#: Body centre to bottom (m) where it is not half the height: a box's floor reaches 4.5 cm below its centre
CENTRE_TO_BOTTOM = {"boxes": 0.045, "boxes_with_lid": 0.045}
TABLE_SIZE = (0.6, 1.2)  # the desk is about 120 cm wide (benchmark x) and 60 cm deep (benchmark z)
SUITE = "gsr-bench"


def to_world(pos: Mapping[str, Any], where: str) -> tuple[float, float, float]:
    """A benchmark centimetre point (three.js frame, +y up) in our metre frame (+x forward, +z up)."""
    try:
        x, y, z = (float(pos[k]) for k in ("x", "y", "z"))
    except (KeyError, TypeError, ValueError):
        raise GSRError(f"{where}: position needs numeric x, y, z") from None
    return (round(-z / 100.0, 5), round(-x / 100.0, 5), round(y / 100.0, 5))


def _color(entry: Mapping[str, Any], where: str) -> str:
    idx = entry.get("colorIndex")
    if isinstance(idx, bool) or not isinstance(idx, int) or not 0 <= idx < len(COLORS):
        raise GSRError(f"{where}: colorIndex must be 0..{len(COLORS) - 1}, got {idx!r}")
    return COLORS[idx]


def _primitive_ids(kind: str, entries: list[Mapping[str, Any]], where: str) -> list[str]:
    """Node ids of a primitive list, numbered per colour in list order as the benchmark does."""
    colors = [_color(e, f"{where}[{i}]") for i, e in enumerate(entries)]
    if kind == "boxes":
        return [f"{c}_box" for c in colors]
    if kind == "boxes_with_lid":
        return [f"{c}_lid_box" for c in colors]
    seen: dict[str, int] = {}
    out = []
    base = PRIMITIVES[kind][0]
    for c in colors:
        seen[c] = seen.get(c, 0) + 1
        out.append(f"{c}_{base}{seen[c]}")
    return out


def _layout(config: Mapping[str, Any], graph: SceneGraph, where: str) -> tuple[Layout, list[str]]:
    ids = {n.id for n in graph.nodes}
    support = {k: e.target for k, e in graph.supports().items()}
    placed: list[PlacedObject] = []
    for kind, (asset, size) in PRIMITIVES.items():
        entries = config.get(kind) or []
        if not isinstance(entries, list):
            raise GSRError(f"{where}: {kind!r} must be a list")
        for node_id, entry in zip(_primitive_ids(kind, entries, f"{where}.{kind}"), entries, strict=True):
            if node_id not in ids or any(p.id == node_id for p in placed):
                continue  # an object the scene graph does not list (or a repeated box colour)
            x, y, z = to_world(entry.get("position") or {}, f"{where}.{kind} {node_id}")
            on = support.get(node_id)
            placed.append(
                PlacedObject(
                    id=node_id,
                    asset=asset,
                    position=(
                        x,
                        y,
                        round(max(0.0, z - DESK_TOP - CENTRE_TO_BOTTOM.get(kind, size[2] / 2)), 5),
                    ),
                    yaw=float(entry.get("rotation") or 0.0),
                    color=node_id.split("_", 1)[0],
                    size=size,
                    on=None if on in (None, "table") else on,
                    joint_states={"lid": 1.0} if entry.get("isOpen") else {},
                )
            )
    for i, entry in enumerate(config.get("libero_assets") or []):
        asset = str(entry.get("assetId", "")).lower()
        if asset not in ids or any(p.id == asset for p in placed):
            continue
        x, y, z = to_world(entry.get("position") or {}, f"{where}.libero_assets[{i}]")
        on = support.get(asset)
        drawers = {
            str(d.get("partName")): (1.0 if d.get("isOpen") else 0.0) for d in entry.get("drawers") or []
        }
        placed.append(
            PlacedObject(
                id=asset,
                asset=asset,
                position=(x, y, 0.0 if on in (None, "table") else z),
                yaw=float(entry.get("rotation") or 0.0),
                size=LIBERO_SIZES.get(asset),
                fixed=entry.get("category") == "articulated",
                on=None if on in (None, "table") else on,
                joint_states=drawers,
            )
        )
    have = {p.id for p in placed}
    unplaced = [n.id for n in graph.nodes if n.parent is None and n.id not in have and n.id != "table"]
    return Layout(objects=tuple(placed), table_size=TABLE_SIZE), unplaced


def _mark_lids(graph: SceneGraph) -> SceneGraph:
    """``*_lid_box`` nodes are lidded (openable) boxes; closed unless the graph says open."""
    nodes = []
    for n in graph.nodes:
        if n.id.endswith("_lid_box") or n.id.endswith("lid_box"):
            states = n.states if {"open", "closed"} & set(n.states) else (*n.states, "closed")
            n = n.model_copy(
                update={"attributes": {**n.attributes, "lid": True}, "states": tuple(sorted(states))}
            )
        nodes.append(n)
    return graph.model_copy(update={"nodes": tuple(nodes)})


def task_from_config(config: Mapping[str, Any], source: str = "<gsr-bench>") -> TaskSpec:
    """One GSR-Bench config as a TaskSpec (errors name the source and the config number)."""
    if not isinstance(config, Mapping):
        raise GSRError(f"{source}: a config must be a mapping, got {type(config).__name__}")
    number = config.get("number", config.get("id"))
    where = f"{source}: config {number}"
    sg = config.get("scene_graph")
    query = config.get("task_query")
    if not isinstance(sg, Mapping):
        raise GSRError(f"{where}: missing scene_graph with nodes and edges")
    if not isinstance(query, str) or not query.strip():
        raise GSRError(f"{where}: missing task_query")
    try:
        graph = _mark_lids(graph_from_gsr_bench(sg))
        goals = goal_for_query(graph, query)
        layout, unplaced = _layout(config, graph, where)
    except GSRError as exc:
        msg = str(exc)
        raise GSRError(msg if msg.startswith(where) else f"{where}: {msg}") from None
    data = {
        "id": f"gsr_bench_{number}",
        "suite": SUITE,
        "category": goals.kind,
        "instructions": [" ".join(query.split())],
        "initial": graph,
        "layout": layout,
        "goal": goals.alternatives[0],
        "goal_alternatives": list(goals.alternatives[1:]),
        "metadata": {
            "source": "gsr-bench",
            "number": number,
            "config_id": config.get("id"),
            "query_kind": goals.kind,
            "goal_objects": list(goals.objects),
            "unplaced": unplaced,
            "units": "converted from benchmark cm (three.js, +y up) to m (+x forward, +z up)",
        },
    }
    return task_from_dict(data, source=where)


def load_configs(path: str | Path) -> list[Mapping[str, Any]]:
    """The config mappings of a GSR-Bench YAML file (``{configs: [...]}``, a list, or one config)."""
    import yaml

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise GSRError(f"{path}: cannot read: {exc.strerror}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise GSRError(f"{path}: invalid YAML: {exc}") from None
    if isinstance(data, Mapping) and "configs" in data:
        data = data["configs"]
    elif isinstance(data, Mapping):
        data = [data]
    if not isinstance(data, list) or not data:
        raise GSRError(f"{path}: expected a 'configs' list of GSR-Bench configs")
    return data


def load_gsr_bench(path: str | Path, numbers: Iterable[int] | None = None) -> list[TaskSpec]:
    """Every config of a GSR-Bench file as a TaskSpec, in file order (optionally only some numbers)."""
    wanted = set(numbers) if numbers is not None else None
    out = []
    for cfg in load_configs(path):
        if wanted is not None and isinstance(cfg, Mapping) and cfg.get("number") not in wanted:
            continue
        out.append(task_from_config(cfg, source=str(path)))
    return out


def yaw_deg(yaw: float) -> float:
    """A yaw in degrees (for reports)."""
    return math.degrees(yaw)
