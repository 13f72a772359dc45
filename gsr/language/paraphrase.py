"""The paraphrase benchmark: everyday instructions written by hand, each with a reference goal.

``data/language/paraphrase_dev.yaml`` (development part) and ``paraphrase_heldout.yaml`` (kept apart)
list scenes (``gsr_bench:<config id>`` of the published dev configs, read from the reference folder and
never copied; ``libero:<suite>/<task>`` of ``data/libero``) and items ``{scene, say, goal}``. An item is
scored by goal equivalence on its scene (:func:`same_goal_states`): the grounded goal and the reference
have the same satisfying states among the states where every object is at one place at a time.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from gsr.errors import GSRError
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.language.equivalence import ground_dnf
from gsr.libero import libero_graph
from gsr.pddl.bddl import load_bddl
from gsr.pddl.model import Formula
from gsr.resources import data_dir, shared_data_dir
from gsr.scene_graph import SceneGraph

PARTS = ("dev", "heldout")
#: Location fluents: an object is in / on / held by at most one thing at a time.
_LOCATION = ("in", "on", "holding")


@dataclass(frozen=True, slots=True)
class Item:
    """One benchmark instruction: the scene it is said in, the words, the reference goal (PDDL text)."""

    part: str
    scene: str
    say: str
    goal: str


def suite_path(part: str) -> Path:
    """The file of one part of the benchmark."""
    if part not in PARTS:
        raise GSRError(f"unknown paraphrase part {part!r} (known: {', '.join(PARTS)})")
    return data_dir() / "language" / f"paraphrase_{part}.yaml"


def load_items(part: str, path: Path | None = None) -> list[Item]:
    """The items of one part (scene aliases resolved to scene sources)."""
    import yaml

    path = path or suite_path(part)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise GSRError(f"{path}: cannot read ({exc.strerror})") from None
    except yaml.YAMLError as exc:
        raise GSRError(f"{path}: not YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict) or not isinstance(data.get("items"), list):
        raise GSRError(f"{path}: expected a mapping with 'scenes' and 'items'")
    scenes = data.get("scenes") or {}
    items = []
    for n, row in enumerate(data["items"], 1):
        if not isinstance(row, dict) or not {"scene", "say", "goal"} <= set(row):
            raise GSRError(f"{path}: item {n}: needs scene, say and goal")
        scene = scenes.get(row["scene"], row["scene"])
        items.append(Item(part, str(scene), str(row["say"]), str(row["goal"])))
    return items


@lru_cache(maxsize=1)
def _gsr_bench_configs() -> dict[str, Any]:
    import yaml

    path = shared_data_dir() / "gsr_bench" / "saved_configs_dev.yaml"
    if not path.is_file():
        raise GSRError(f"GSR-Bench dev configs not found at {path}: set GSR_SHARED_DATA")
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    return {str(c["id"]): c for c in data["configs"]}


@lru_cache(maxsize=256)
def scene_graph(source: str) -> SceneGraph:
    """The start graph of a scene source (``gsr_bench:<id>`` or ``libero:<suite>/<task>``)."""
    kind, _, ref = source.partition(":")
    if kind == "gsr_bench":
        config = _gsr_bench_configs().get(ref)
        if config is None:
            raise GSRError(f"no GSR-Bench dev config with id {ref}")
        return graph_from_gsr_bench(config["scene_graph"])
    if kind == "libero":
        path = data_dir() / "libero" / f"{ref}.bddl"
        if not path.is_file():
            raise GSRError(f"no LIBERO task file {path}")
        return libero_graph(load_bddl(path))
    raise GSRError(f"unknown scene source {source!r} (gsr_bench:<id> or libero:<suite>/<task>)")


# ------------------------------------------------------------------ equivalence


def same_goal_states(a: Formula, b: Formula, graph: SceneGraph) -> bool:
    """Whether two goals hold in the same states of the scene.

    Both are compiled to ground DNFs (:func:`gsr.language.equivalence.ground_dnf`); equal DNFs are
    equivalent. Otherwise each side must entail the other, checked by satisfiability over the fluent
    atoms they mention, with the invariant that an object is at one place at a time (two location
    atoms of one object are never both true).
    """
    da, db = ground_dnf(a, graph), ground_dnf(b, graph)
    if da == db:
        return True
    atoms = sorted({atom for term in da | db for atom, _ in term}, key=str)
    index = {atom: i + 1 for i, atom in enumerate(atoms)}
    mutex = _mutex_clauses(atoms, index)
    return _entails(da, db, index, mutex) and _entails(db, da, index, mutex)


def _mutex_clauses(atoms: list, index: dict) -> list[frozenset[int]]:
    by_object: dict[str, list[int]] = {}
    for atom in atoms:
        if atom.predicate in _LOCATION and atom.args:
            by_object.setdefault(atom.args[0], []).append(index[atom])
    return [
        frozenset((-x, -y)) for ids in by_object.values() for i, x in enumerate(ids) for y in ids[i + 1 :]
    ]


def _entails(da: frozenset, db: frozenset, index: dict, mutex: list) -> bool:
    """Every state (meeting the invariant) satisfying a DNF term of ``da`` satisfies ``db``."""
    not_b = [frozenset(-index[atom] if value else index[atom] for atom, value in term) for term in db]
    for term in da:
        units = [frozenset({index[atom] if value else -index[atom]}) for atom, value in term]
        if _satisfiable(units + mutex) and _satisfiable(units + mutex + not_b):
            return False
    return True


def _satisfiable(clauses: list[frozenset[int]]) -> bool:
    """DPLL with unit propagation over integer literals."""
    clauses = list(clauses)
    assignment: set[int] = set()
    while True:
        if any(not c for c in clauses):
            return False
        unit = next((c for c in clauses if len(c) == 1), None)
        if unit is None:
            break
        (lit,) = unit
        assignment.add(lit)
        clauses = [c - {-lit} for c in clauses if lit not in c]
    if not clauses:
        return True
    lit = next(iter(clauses[0]))
    return _satisfiable([*clauses, frozenset({lit})]) or _satisfiable([*clauses, frozenset({-lit})])
