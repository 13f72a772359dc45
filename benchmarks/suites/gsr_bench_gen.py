"""Seeded generator of the nine GSR-Bench cells (3 task types x Simple / General / Complex, 20 each).

Tasks are emitted as configs in the public GSR-Bench format (object lists with centimetre positions,
scene-graph strings, ``task_query``) and imported with the same importer and query semantics as the
real benchmark (:mod:`gsr.benchmarks.suites.gsr_bench`), so generated and published tasks mean the same.

Cell definitions (ours, following the published cell names; every task moves enough objects that an
optimal plan needs more than 10 steps):

* Semantic Object Disambiguation — the query singles objects out by colour and kind among distractors
  that share one of the two. Simple: ``move all C_cubes into D_box`` (6-8 targets, other-colour cubes).
  General: ``move all C_mugs into drawer_X`` (same-colour cubes, other-colour mugs and LIBERO mugs as
  distractors; the drawer starts closed). Complex: ``Put all the mugs and cubes into their
  corresponding colored boxes`` with stacked boxes, objects already in wrong boxes and LIBERO clutter.
* Spatial-Aware Sequencing — validity rules force an order. Simple: target is a closed lidded box with an
  object lying on its lid. General: ``move all cubes into drawer_low`` while upper drawers are open and
  some cubes sit in them (take out, close, then open the low one). Complex: targets spread over a closed
  lidded box with something on the lid, an open upper drawer and the table, into ``drawer_low``.
* Goal-conditioned Generalization — abstract goals. Simple: ``put all items on the table into the
  C_box``. General: ``place the milk, the popcorn, and the book into different drawer layers`` with the
  book in a closed lidded box under a mug and the top drawer open. Complex: ``Put all the cubes and mugs
  into the drawers by color - one color per drawer level`` with objects in boxes and open drawers.
"""

from __future__ import annotations

import random
from typing import Any

from gsr.benchmarks.suites.gsr_bench import task_from_config

from gsr.task_spec import TaskSpec

SUITE = "gsr-bench-gen"
CELLS = ("Semantic Object Disambiguation", "Spatial-Aware Sequencing", "Goal-conditioned Generalization")
LEVELS = ("Simple", "General", "Complex")
COLORS = ("red", "yellow", "blue")
CAB = "short_cabinet"
DRAWERS = ("drawer_low", "drawer_middle", "drawer_high")
HALF = {"cubes": 3.5, "mugs": 4.5, "boxes": 6.5, "boxes_with_lid": 6.5}


class _Config:
    """Builds one config in the benchmark's format (lists in order, names numbered per colour)."""

    def __init__(self, rng: random.Random) -> None:
        self.rng = rng
        self.lists: dict[str, list[dict[str, Any]]] = {
            k: [] for k in ("boxes", "boxes_with_lid", "mugs", "cubes")
        }
        self.assets: list[dict[str, Any]] = []
        self.nodes: list[str] = ["table"]
        self.edges: list[str] = []
        self.count: dict[tuple[str, str], int] = {}
        self.where: dict[str, tuple[float, float, float]] = {}
        self.used: list[tuple[float, float]] = []

    def _spot(self) -> tuple[float, float]:
        for _ in range(200):
            x, z = self.rng.uniform(-50, 50), self.rng.uniform(-22, 22)
            if all((x - a) ** 2 + (z - b) ** 2 > 12**2 for a, b in self.used):
                break
        self.used.append((x, z))
        return round(x, 3), round(z, 3)

    def _pos(self, kind: str, rel: str, holder: str) -> dict[str, float]:
        if holder == "table":
            x, z = self._spot()
            y = HALF.get(kind, 5.0)
        else:
            hx, hy, hz = self.where.get(holder, (0.0, 0.0, 0.0))
            x, z = hx + self.rng.uniform(-3, 3), hz + self.rng.uniform(-3, 3)
            y = hy + (2.0 if rel == "in" else 8.0)
        self.where[f"{len(self.where)}"] = (x, y, z)
        return {"x": round(x, 3), "y": round(y, 3), "z": round(z, 3)}

    def add(
        self, kind: str, color: str, rel: str = "on", holder: str = "table", state: str | None = None
    ) -> str:
        """A primitive (cube, mug, box, lidded box) of a colour resting ``rel`` ``holder``; its node id."""
        idx = COLORS.index(color)
        if kind == "boxes":
            name = f"{color}_box"
        elif kind == "boxes_with_lid":
            name = f"{color}_lid_box"
        else:
            n = self.count.get((kind, color), 0) + 1
            self.count[(kind, color)] = n
            name = f"{color}_{kind[:-1]}{n}"
        pos = self._pos(kind, rel, holder)
        entry: dict[str, Any] = {
            "position": pos,
            "rotation": round(self.rng.uniform(-3.14, 3.14), 4),
            "colorIndex": idx,
        }
        if kind == "boxes_with_lid":
            entry.update({"name": name, "isOpen": state == "open"})
        elif kind == "boxes":
            entry.update({"isStacked": holder != "table", "stackedOn": None})
        else:
            entry.update(
                {"placement": "on_table" if holder == "table" else f"{rel}_box", "targetBoxIndex": None}
            )
        self.lists[kind].append(entry)
        self.where[name] = (pos["x"], pos["y"], pos["z"])
        self.nodes.append(f"{name}({state})" if state else name)
        self.edges.append(f"{name}({rel}){holder}")
        return name

    def asset(self, asset_id: str, rel: str = "on", holder: str = "table") -> str:
        """A LIBERO asset (milk, popcorn, yellow_book, red_coffee_mug ...)."""
        pos = self._pos("asset", rel, holder)
        self.assets.append({"assetId": asset_id, "category": "hope", "position": pos, "rotation": 0.0})
        self.where[asset_id] = (pos["x"], pos["y"], pos["z"])
        self.nodes.append(asset_id)
        self.edges.append(f"{asset_id}({rel}){holder}")
        return asset_id

    def cabinet(self, open_drawers: tuple[str, ...] = ()) -> dict[str, str]:
        """The short cabinet with its three drawers; part name -> node id."""
        x, z = self._spot()
        drawers = [{"partName": d, "isOpen": d in open_drawers} for d in DRAWERS]
        self.assets.append(
            {
                "assetId": CAB,
                "category": "articulated",
                "position": {"x": x, "y": 11.5, "z": z},
                "rotation": 0.0,
                "drawers": drawers,
            }
        )
        self.where[CAB] = (x, 11.5, z)
        self.nodes.append(CAB)
        self.edges.append(f"{CAB}(on)table")
        out = {}
        for d in DRAWERS:
            node = f"{CAB}/{d}"
            self.nodes.append(f"{node}({'open' if d in open_drawers else 'closed'})")
            self.where[node] = (x, 11.5, z)
            out[d] = node
        return out

    def config(self, number: int, query: str) -> dict[str, Any]:
        """The finished config mapping."""
        return {
            "id": number,
            "number": number,
            "name": f"generated_{number}",
            **self.lists,
            "libero_assets": self.assets,
            "scene_graph": {"nodes": self.nodes, "edges": self.edges},
            "task_query": query,
        }


def _others(color: str) -> list[str]:
    return [c for c in COLORS if c != color]


def _sod(c: _Config, level: int, rng: random.Random) -> str:
    color = rng.choice(COLORS)
    if level == 0:
        box = rng.choice(COLORS)
        c.add("boxes", box)
        for _ in range(rng.randint(6, 8)):
            c.add("cubes", color)
        for _ in range(rng.randint(3, 5)):
            c.add("cubes", rng.choice(_others(color)))
        return f"move all {color}_cubes into {box}_box."
    if level == 1:
        drawer = rng.choice(DRAWERS)
        c.cabinet()
        for _ in range(rng.randint(5, 6)):
            c.add("mugs", color)
        for _ in range(3):
            c.add("cubes", color)
            c.add("mugs", rng.choice(_others(color)))
        c.asset("red_coffee_mug" if color != "red" else "porcelain_mug")
        return f"move all {color}_mugs into {drawer}"
    bottom, mid, top = rng.sample(COLORS, 3)
    c.add("boxes", bottom)
    c.add("boxes", mid, "on", f"{bottom}_box")
    c.add("boxes", top)
    for col in COLORS:
        for _ in range(2):
            holder = rng.choice([f"{o}_box" for o in _others(col)] + ["table", "table"])
            c.add(rng.choice(("cubes", "mugs")), col, "in" if holder != "table" else "on", holder)
        c.add("cubes", col)
    for a in ("milk", "popcorn", "yellow_book"):
        c.asset(a)
    return "Put all the mugs and cubes into their corresponding colored boxes"


def _sas(c: _Config, level: int, rng: random.Random) -> str:
    color, other = rng.sample(COLORS, 2)
    if level == 0:
        c.add("boxes_with_lid", other, state="closed")
        c.asset("milk", "on", f"{other}_lid_box")
        for _ in range(rng.randint(5, 6)):
            c.add("cubes", color)
        for _ in range(3):
            c.add("cubes", other)
        return f"move all {color}_cubes into {other}_lid_box."
    if level == 1:
        d = c.cabinet(open_drawers=("drawer_middle", "drawer_high"))
        for col in COLORS:
            c.add("cubes", col, "in", d["drawer_high"])
        c.add("cubes", color, "in", d["drawer_middle"])
        for _ in range(2):
            c.add("cubes", rng.choice(COLORS))
        c.add("mugs", other)
        return "move all cubes into drawer_low"
    d = c.cabinet(open_drawers=("drawer_high",))
    c.add("boxes_with_lid", other, state="closed")
    c.add("mugs", other, "on", f"{other}_lid_box")
    for _ in range(2):
        c.add("cubes", color, "in", f"{other}_lid_box")
    for _ in range(2):
        c.add("cubes", color, "in", d["drawer_high"])
    for _ in range(2):
        c.add("cubes", color)
    c.add("cubes", other)
    return f"move all {color}_cubes into drawer_low"


def _gcg(c: _Config, level: int, rng: random.Random) -> str:
    if level == 0:
        box = rng.choice(COLORS)
        c.add("boxes", box)
        for _ in range(rng.randint(3, 4)):
            c.add("cubes", rng.choice(COLORS))
        for _ in range(2):
            c.add("mugs", rng.choice(COLORS))
        c.asset(rng.choice(("milk", "popcorn")))
        c.add("cubes", rng.choice(COLORS), "in", f"{box}_box")
        return f"put all items on the table into the {box}_box"
    if level == 1:
        c.cabinet(open_drawers=("drawer_high",))
        lid = rng.choice(COLORS)
        c.add("boxes_with_lid", lid, state="closed")
        c.asset("yellow_book", "in", f"{lid}_lid_box")
        # a mug, not a cube, on the lid: GSR-Bench never lets a cube off anything but the table
        c.add("mugs", rng.choice(COLORS), "on", f"{lid}_lid_box")
        c.asset("milk")
        c.asset("popcorn")
        c.add("mugs", rng.choice(COLORS))
        return "place the milk, the popcorn, and the book into different drawer layers of the cabinet."
    d = c.cabinet(open_drawers=rng.choice([("drawer_high",), ("drawer_middle",), ()]))
    holder_box = rng.choice(COLORS)
    c.add("boxes", holder_box)
    for col in COLORS:
        c.add("cubes", col)
        c.add("mugs", col, "in", f"{holder_box}_box") if rng.random() < 0.5 else c.add("mugs", col)
    c.add("cubes", rng.choice(COLORS), "in", d["drawer_low"])
    c.asset("milk")
    return "Put all the cubes and mugs into the drawers by color—one color per drawer level"


_BUILD = {CELLS[0]: _sod, CELLS[1]: _sas, CELLS[2]: _gcg}


def cell_configs(cell: str, level: str, n: int = 20, seed: int = 0) -> list[dict[str, Any]]:
    """The configs of ``n`` tasks of one cell in the public GSR-Bench format, deterministic for ``seed``
    (numbered 1000 * cell index + k)."""
    configs = []
    li = LEVELS.index(level)
    for k in range(n):
        rng = random.Random(f"{seed}:{cell}:{level}:{k}")
        cfg = _Config(rng)
        query = _BUILD[cell](cfg, li, rng)
        configs.append(cfg.config(1000 * (CELLS.index(cell) * 3 + li + 1) + k, query))
    return configs


def generate_configs(seed: int = 0, per_cell: int = 20) -> list[dict[str, Any]]:
    """The configs of all nine cells (a ``configs:`` list as in the benchmark's saved_configs.yaml)."""
    return [c for cell in CELLS for level in LEVELS for c in cell_configs(cell, level, per_cell, seed)]


def generate_cell(cell: str, level: str, n: int = 20, seed: int = 0) -> list[TaskSpec]:
    """``n`` tasks of one cell, deterministic for ``seed``."""
    tasks = []
    for k, config in enumerate(cell_configs(cell, level, n, seed)):
        task = task_from_config(config, source=f"generated {cell}/{level}")
        slug = "".join(w[0] for w in cell.split()).lower()
        tasks.append(
            task.model_copy(
                update={
                    "id": f"gsrgen_{slug}_{level.lower()}_{k:02d}",
                    "suite": SUITE,
                    "category": cell,
                    "level": level,
                    "metadata": {**task.metadata, "source": "generated", "seed": seed, "index": k},
                }
            )
        )
    return tasks


def generate_gsr_bench(seed: int = 0, per_cell: int = 20) -> list[TaskSpec]:
    """All nine cells (180 tasks by default), deterministic for ``seed``."""
    return [t for cell in CELLS for level in LEVELS for t in generate_cell(cell, level, per_cell, seed)]
