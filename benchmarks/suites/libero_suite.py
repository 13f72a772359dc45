"""LIBERO suite: every BDDL task file of a folder (recursively) becomes a TaskSpec.

The scene graph and goal come from :func:`gsr.libero.libero_task` (regions resolved to parts of the
tabletop domain); the instruction is the file's ``:language``. The layout keeps LIBERO's regions
(``(:ranges ((x0 y0 x1 y1)))`` in metres on their target, LIBERO's table frame: +x away from the robot,
+y left) and places every object and fixture at the centre of the first range of the region its init
fact names, or on the object it starts on or in.
"""

from __future__ import annotations

from pathlib import Path

from gsr.errors import GSRError
from gsr.libero import libero_task
from gsr.pddl.bddl import BddlProblem, load_bddl
from gsr.pddl.writer import write_formula
from gsr.task_spec import Layout, PlacedObject, Region, TaskSpec, task_from_dict

SUITE = "libero"


def _is_surface(name: str) -> bool:
    return name == "floor" or name.endswith("table")


def _regions(bddl: BddlProblem) -> tuple[list[Region], dict[str, Region]]:
    regions: list[Region] = []
    by_ref: dict[str, Region] = {}
    for r in bddl.regions:
        if not r.ranges or len(r.ranges[0]) != 4:
            continue  # object sites without a footprint (contain_region of a basket) place nothing
        x0, y0, x1, y1 = (float(v) for v in r.ranges[0])
        yaw = float(r.yaw_rotation[0][0]) if r.yaw_rotation and r.yaw_rotation[0] else 0.0
        region = Region(
            name=r.qualified_name.lower(),
            target=r.target.lower(),
            bounds=(min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)),
            yaw=yaw,
        )
        if region.name not in by_ref:
            regions.append(region)
            by_ref[region.name] = region
    return regions, by_ref


def _layout(bddl: BddlProblem, support: dict[str, str]) -> Layout:
    """Regions, and every object at its init region's centre; ``on`` is its support node in the graph."""
    regions, by_ref = _regions(bddl)
    region_target = {r.qualified_name.lower(): r.target.lower() for r in bddl.regions}
    objects = {**{k.lower(): (v, True) for k, v in bddl.fixtures.items()}}
    objects.update({k.lower(): (v, False) for k, v in bddl.objects.items()})
    where: dict[str, str] = {}
    for atom in bddl.init:
        if atom.predicate in ("on", "in") and len(atom.args) == 2:
            where.setdefault(atom.args[0].lower(), atom.args[1].lower())
    placed: dict[str, PlacedObject] = {}

    def place(name: str, depth: int = 0) -> PlacedObject | None:
        if name in placed:
            return placed[name]
        kind, fixture = objects[name]
        ref = where.get(name)
        pos, on = (0.0, 0.0, 0.0), None
        if ref in by_ref and (by_ref[ref].target not in objects or _is_surface(by_ref[ref].target)):
            # a footprint on the table (or floor): the object stands at its centre
            x0, y0, x1, y1 = by_ref[ref].bounds
            pos = (round((x0 + x1) / 2, 5), round((y0 + y1) / 2, 5), 0.0)
        elif ref is not None:
            holder = ref if ref in objects else region_target.get(ref)
            if holder in objects and holder != name and depth < 8:
                parent = place(holder, depth + 1)
                if parent is not None:
                    pos, on = parent.position, holder
        holder = support.get(name, on)
        holder = None if holder is None or _is_surface(holder) else holder
        obj = PlacedObject(id=name, asset=kind.lower(), position=pos, fixed=fixture, on=holder)
        placed[name] = obj
        return obj

    for name in objects:
        if not _is_surface(name):
            place(name)
    return Layout(objects=tuple(placed[n] for n in objects if n in placed), regions=tuple(regions))


def task_from_bddl(path: str | Path, suite_name: str | None = None) -> TaskSpec:
    """One LIBERO BDDL file as a TaskSpec (category = its LIBERO suite folder)."""
    path = Path(path)
    bddl = load_bddl(path)
    if not bddl.language:
        raise GSRError(f"{path}: LIBERO task has no :language instruction")
    try:
        graph, problem = libero_task(bddl)
    except GSRError as exc:
        raise GSRError(f"{path}: {exc}") from None
    category = suite_name or path.parent.name
    data = {
        "id": f"libero_{category}_{path.stem}".lower(),
        "suite": SUITE,
        "category": category,
        "instructions": [" ".join(bddl.language.split())],
        "initial": graph,
        "layout": _layout(bddl, {e.source: e.target for e in graph.edges if e.relation in ("on", "in")}),
        "goal": write_formula(problem.goal),
        "metadata": {"source": "libero", "file": path.name, "problem": bddl.name},
    }
    return task_from_dict(data, source=str(path))


def load_libero(folder: str | Path) -> list[TaskSpec]:
    """Every ``*.bddl`` under ``folder`` (sorted) as a TaskSpec."""
    folder = Path(folder)
    if folder.is_file():
        return [task_from_bddl(folder)]
    if not folder.is_dir():
        raise GSRError(f"{folder}: no such LIBERO folder")
    files = sorted(folder.rglob("*.bddl"))
    if not files:
        raise GSRError(f"{folder}: no .bddl task files found")
    return [task_from_bddl(f) for f in files]
