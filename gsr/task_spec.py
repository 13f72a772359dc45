"""TaskSpec: one benchmark task — instruction(s), initial scene graph, physical layout, goal formula.

TaskSpec lives in the core (not in ``benchmarks/``) because every layer reads it: the simulator builds a
world from its layout (``skills``), the suites produce it (``benchmarks``), the dataset generator may emit
it. It is plain data (pydantic, JSON/YAML); goals are stored as PDDL formula text over the graph's node ids
so a spec file is readable and diffable, and parsed on demand.

Units: metres and radians, world frame with +x forward (away from the robot base), +y left, +z up; the
table top is the plane z = ``Layout.table_height``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from gsr.errors import GSRError, ParseError
from gsr.pddl.model import Formula
from gsr.pddl.parser import parse_formula
from gsr.scene_graph import SceneGraph, format_validation_error


class PlacedObject(BaseModel):
    """An object of the layout: which asset, where, and how it looks (``id`` is its scene-graph node id)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    id: str
    asset: str = Field(description="asset/catalog name, e.g. 'cube', 'box_with_lid', 'cabinet_3_drawers'")
    position: tuple[float, float, float] = Field(description="x, y, z of the object's base centre (m)")
    yaw: float = 0.0
    color: str | None = None
    size: tuple[float, float, float] | None = Field(
        default=None, description="extent x, y, z (m), if not the asset's"
    )
    fixed: bool = Field(default=False, description="a fixture (cabinet, stove, table): not movable")
    on: str | None = Field(
        default=None, description="id of what it initially rests on or in, if not the table"
    )
    joint_states: dict[str, float] = Field(default_factory=dict, description="part name -> joint position")


class Region(BaseModel):
    """A named placement area (LIBERO regions): an axis-aligned rectangle on a surface."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str
    target: str = Field(description="what the region lies on or in (table, an object or a part)")
    bounds: tuple[float, float, float, float] = Field(description="xmin, ymin, xmax, ymax (m)")
    yaw: float = 0.0


class Layout(BaseModel):
    """The physical scene for the simulator: objects, regions and the table."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    objects: tuple[PlacedObject, ...] = ()
    regions: tuple[Region, ...] = ()
    table_size: tuple[float, float] = (1.2, 1.6)
    table_height: float = 0.0
    seed: int = 0

    @model_validator(mode="after")
    def _unique(self) -> Layout:
        seen: set[str] = set()
        for o in self.objects:
            if o.id in seen:
                raise ValueError(f"duplicate layout object id {o.id!r}")
            seen.add(o.id)
        return self

    def object(self, object_id: str) -> PlacedObject:
        """The placed object ``object_id`` (KeyError if absent)."""
        for o in self.objects:
            if o.id == object_id:
                return o
        raise KeyError(object_id)


class TaskSpec(BaseModel):
    """One task of a suite: instruction(s), initial graph, optional layout, goal and goal alternatives."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    id: str
    suite: str
    category: str = ""
    level: str | None = None
    instructions: tuple[str, ...] = Field(min_length=1)
    initial: SceneGraph
    layout: Layout | None = None
    goal: str = Field(
        description="PDDL goal formula over node ids, e.g. '(and (in bowl_1 cabinet_1/bottom_drawer))'"
    )
    goal_alternatives: tuple[str, ...] = Field(
        default=(), description="further acceptable goals (GenManip-style); the best one scores"
    )
    metadata: dict[str, Any] = Field(default_factory=dict)

    @field_validator("goal", "goal_alternatives")
    @classmethod
    def _parses(cls, v: str | tuple[str, ...]) -> str | tuple[str, ...]:
        for text in (v,) if isinstance(v, str) else v:
            try:
                parse_formula(text, source="goal")
            except ParseError as exc:  # re-raise as ValueError so pydantic names the field
                raise ValueError(str(exc)) from None
        return v

    @property
    def instruction(self) -> str:
        """The first (canonical) instruction."""
        return self.instructions[0]

    def goal_formula(self) -> Formula:
        """The goal parsed into a formula."""
        return parse_formula(self.goal, source=f"{self.id}:goal")

    def goal_formulas(self) -> tuple[Formula, ...]:
        """The goal followed by its alternatives, parsed."""
        alternatives = (
            parse_formula(t, source=f"{self.id}:goal_alternatives") for t in self.goal_alternatives
        )
        return (self.goal_formula(), *alternatives)


def task_from_dict(data: Any, source: str = "<task>") -> TaskSpec:
    """Validate a mapping into a TaskSpec; errors name the source and the offending field."""
    try:
        return TaskSpec.model_validate(data)
    except ValidationError as exc:
        raise GSRError(f"{source}: invalid task: {format_validation_error(exc)}") from None


def load_task(path: str | Path) -> TaskSpec:
    """Read a TaskSpec from a JSON or YAML file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise GSRError(f"{path}: cannot read: {exc.strerror}") from None
    if not text.strip():
        raise GSRError(f"{path}: empty file")
    if path.suffix.lower() in (".yaml", ".yml"):
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise GSRError(f"{path}: invalid YAML: {exc}") from None
    else:
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise GSRError(f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
    return task_from_dict(data, source=str(path))


def task_json(task: TaskSpec) -> str:
    """The TaskSpec as indented JSON (round-trips through ``task_from_dict``)."""
    return task.model_dump_json(indent=2, exclude_none=True)
