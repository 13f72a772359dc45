"""Reading the PRS delivery benchmark's station files with one clear error per bad file or field.

PRS (``PRS-Organization/prs-delivery``, ``env/data``) describes its research station in a handful of JSON
files and one tab-separated semantic grid per floor. This module only reads and validates them; the
station model built from them lives in ``gsr.benchmarks.delivery.building.prs``. No PRS file is shipped with GSR: the user
names the folder.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gsr.errors import GSRError

#: The files a PRS data folder must hold (semantic grids are found per floor as ``semantic_map_<n>.txt``).
REQUIRED = (
    "room_mapping.json",
    "map_room_data.json",
    "map_receptacle_data.json",
    "semantic_map_tags.json",
    "npc_data.json",
    "npc_schedule.json",
)


class PrsDataError(GSRError):
    """A PRS data file that is missing or malformed; the message names the file and the field."""

    def __init__(self, path: Path | str, field: str | None, problem: str) -> None:
        where = f"{path}" if field is None else f"{path}: {field}"
        super().__init__(f"{where}: {problem}")
        self.path = str(path)
        self.field = field


def read_json(path: Path) -> Any:
    """Parse a JSON file; missing file or bad JSON -> ``PrsDataError`` naming it."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PrsDataError(path, None, "file not found") from None
    except OSError as exc:
        raise PrsDataError(path, None, f"cannot read: {exc.strerror}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise PrsDataError(
            path, None, f"bad JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None


def need(obj: Any, key: str, kind: type | tuple[type, ...], path: Path, field: str) -> Any:
    """``obj[key]`` checked to be of ``kind``; else ``PrsDataError`` naming ``field``."""
    if not isinstance(obj, dict) or key not in obj:
        raise PrsDataError(path, field, "missing")
    value = obj[key]
    if not isinstance(value, kind) or (isinstance(value, bool) and bool not in _as_tuple(kind)):
        names = "/".join(k.__name__ for k in _as_tuple(kind))
        raise PrsDataError(path, field, f"expected {names}, got {type(value).__name__}")
    return value


def _as_tuple(kind: type | tuple[type, ...]) -> tuple[type, ...]:
    return kind if isinstance(kind, tuple) else (kind,)


def int_range(value: Any, path: Path, field: str) -> tuple[int, int]:
    """A ``[lo, hi]`` pair of integers (inclusive grid extent)."""
    if (
        not isinstance(value, list)
        or len(value) != 2
        or not all(isinstance(v, int) and not isinstance(v, bool) for v in value)
        or value[0] > value[1]
    ):
        raise PrsDataError(path, field, f"expected [lo, hi] integers with lo <= hi, got {value!r}")
    return (value[0], value[1])


def read_grid(path: Path) -> np.ndarray:
    """A semantic map: rows of tab-separated non-negative integers, all rows the same length."""
    try:
        lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    except FileNotFoundError:
        raise PrsDataError(path, None, "file not found") from None
    except OSError as exc:
        raise PrsDataError(path, None, f"cannot read: {exc.strerror}") from None
    if not lines:
        raise PrsDataError(path, None, "empty grid")
    rows: list[list[int]] = []
    for n, line in enumerate(lines):
        try:
            row = [int(v) for v in line.split("\t")]
        except ValueError:
            raise PrsDataError(path, f"row {n}", "non-integer cell value") from None
        if rows and len(row) != len(rows[0]):
            raise PrsDataError(path, f"row {n}", f"{len(row)} cells, row 0 has {len(rows[0])}")
        if min(row) < 0:
            raise PrsDataError(path, f"row {n}", "negative cell value")
        rows.append(row)
    return np.asarray(rows, dtype=np.int32)


def floor_levels(folder: Path) -> list[int]:
    """The floor numbers with a ``semantic_map_<n>.txt`` in ``folder``, sorted."""
    levels = []
    for p in folder.glob("semantic_map_*.txt"):
        suffix = p.stem.rsplit("_", 1)[-1]
        if suffix.isdigit():
            levels.append(int(suffix))
    return sorted(levels)


def check_folder(folder: Path) -> None:
    """The folder exists and holds every required file and at least one semantic map."""
    if not folder.is_dir():
        raise PrsDataError(folder, None, "not a folder (expected a PRS data folder, e.g. env/data)")
    for name in REQUIRED:
        if not (folder / name).is_file():
            raise PrsDataError(folder / name, None, "file not found")
    if not floor_levels(folder):
        raise PrsDataError(folder / "semantic_map_0.txt", None, "file not found (no semantic_map_<n>.txt)")
