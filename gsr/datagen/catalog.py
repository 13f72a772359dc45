"""The object catalog (``data/catalog/objects.json``): object types the dataset generator places in scenes.

Each entry names a scene-graph category of :mod:`gsr.categories` (so the PDDL type and the static
affordance facts come from the registry), the colours it comes in, its extent in metres, material,
a role (``fixture``, ``container``, ``supporter`` or ``item``), articulated parts and functional
keypoints. Loading checks every entry against the registry: a catalog whose affordances disagree
with the domain would make the generator emit plans the checker rejects.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from gsr.categories import COLORS, affordances, is_category
from gsr.errors import GSRError
from gsr.resources import data_dir
from gsr.scene_graph import format_validation_error

ROLES = ("fixture", "container", "supporter", "item")


class CatalogPart(BaseModel):
    """An articulated part or region of a fixture (a drawer, a burner, a switch)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str
    category: str
    level: int | None = None
    affordances: tuple[str, ...] = ()
    keypoints: tuple[str, ...] = ()


class CatalogEntry(BaseModel):
    """One object type of the catalog."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str
    category: str
    role: str
    colors: tuple[str, ...] = Field(min_length=1)
    size: tuple[float, float, float]
    material: str
    affordances: tuple[str, ...] = ()
    parts: tuple[CatalogPart, ...] = ()
    keypoints: tuple[str, ...] = ()

    @field_validator("role")
    @classmethod
    def _role(cls, v: str) -> str:
        if v not in ROLES:
            raise ValueError(f"unknown role {v!r}; expected one of {', '.join(ROLES)}")
        return v

    @field_validator("colors")
    @classmethod
    def _colors(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        bad = [c for c in v if c not in COLORS]
        if bad:
            raise ValueError(f"colours {bad} are not in the palette ({', '.join(COLORS)})")
        return v

    @property
    def node_category(self) -> str:
        """The scene-graph category of instances: the registry category, or the name for plain things."""
        return self.name if self.category == "thing" else self.category


class Catalog(BaseModel):
    """The whole catalog, with lookups by role."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    version: int
    description: str = ""
    objects: tuple[CatalogEntry, ...]

    def by_role(self, role: str) -> tuple[CatalogEntry, ...]:
        """Entries with this role, in file order."""
        return tuple(o for o in self.objects if o.role == role)

    def entry(self, name: str) -> CatalogEntry:
        """The entry called ``name``; KeyError naming it if absent."""
        for o in self.objects:
            if o.name == name:
                return o
        raise KeyError(f"no catalog entry {name!r}")


def default_catalog_path() -> Path:
    """``data/catalog/objects.json`` of the installed data directory."""
    return data_dir() / "catalog" / "objects.json"


def _expected(category: str, part: bool) -> set[str]:
    aff = set(affordances(category))
    if part:
        aff -= {"movable", "pushable"}
    return aff


def check_catalog(catalog: Catalog, source: str) -> None:
    """Raise GSRError when an entry's category or affordances disagree with the category registry."""
    seen: set[str] = set()
    for i, o in enumerate(catalog.objects):
        where = f"{source}: objects.{i} ({o.name})"
        if o.name in seen:
            raise GSRError(f"{where}: duplicate name")
        seen.add(o.name)
        if not is_category(o.category):
            raise GSRError(f"{where}: category {o.category!r} is not in gsr.categories")
        want = _expected(o.category, part=False)
        if o.role == "fixture":
            want -= {"movable", "pushable"}
        if set(o.affordances) != want:
            raise GSRError(
                f"{where}: affordances {sorted(o.affordances)} differ from the registry's {sorted(want)}"
            )
        if o.role != "fixture" and "movable" not in want:
            raise GSRError(f"{where}: role {o.role!r} needs a movable category, {o.category!r} is not")
        for j, p in enumerate(o.parts):
            if not is_category(p.category):
                raise GSRError(f"{where}: parts.{j} category {p.category!r} is not in gsr.categories")
            if set(p.affordances) != _expected(p.category, part=True):
                raise GSRError(f"{where}: parts.{j} ({p.name}) affordances differ from the registry's")


def load_catalog(path: str | Path | None = None) -> Catalog:
    """Read and check a catalog file (the shipped one by default)."""
    p = Path(path) if path is not None else default_catalog_path()
    return _load(str(p))


@lru_cache(maxsize=8)
def _load(path: str) -> Catalog:
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise GSRError(f"{path}: cannot read catalog: {exc.strerror}") from None
    except json.JSONDecodeError as exc:
        raise GSRError(f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
    try:
        catalog = Catalog.model_validate(data)
    except ValidationError as exc:
        raise GSRError(f"{path}: invalid catalog: {format_validation_error(exc)}") from None
    check_catalog(catalog, path)
    return catalog
