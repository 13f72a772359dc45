"""The shipped three-floor building (``data/buildings/three_floor.json``) and how it was made."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from gsr.benchmarks.delivery.building.model import Building, load_building

from gsr.errors import GSRError
from gsr.resources import data_dir

#: ``gsr delivery generate-building --seed 7 --name three-floor --out data/buildings/three_floor.json``
SHIPPED_SEED = 7
SHIPPED_NAME = "three-floor"


def shipped_building_path() -> Path:
    """Path of the shipped building JSON."""
    path = data_dir() / "buildings" / "three_floor.json"
    if not path.is_file():
        raise GSRError(f"{path}: shipped building missing (regenerate: see data/buildings/README.md)")
    return path


@lru_cache(maxsize=1)
def load_shipped_building() -> Building:
    """The shipped three-floor building (parsed once)."""
    return load_building(shipped_building_path())
