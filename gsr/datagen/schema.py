"""The dataset's stable JSON schemas (pydantic): one envelope, five sample types.

Every JSONL row is a :class:`SampleRow`: flat string columns, with ``input`` and ``output`` holding
JSON text whose shape depends on ``type`` (flat columns keep ``datasets.load_dataset("json")``
schema inference stable across shards). :func:`decode` turns a row into typed models. Graphs use the
``SceneGraph`` JSON layout; atoms are PDDL text ``(on a b)``; steps are ``{action, args, add, delete}``.
Bump :data:`SCHEMA_VERSION` on any incompatible change.
"""

from __future__ import annotations

import json
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from gsr.errors import GSRError
from gsr.scene_graph import SceneGraph, format_validation_error

SCHEMA_VERSION = 1
SAMPLE_TYPES: tuple[str, ...] = (
    "scene_abstraction",
    "next_action",
    "forward_prediction",
    "inverse_action",
    "goal_interpretation",
)
SPLITS: tuple[str, ...] = ("train", "val", "test")
HELDOUT_KINDS: tuple[str, ...] = ("pair", "color", "horizon")


class _Model(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class StepData(_Model):
    """A ground step; ``add``/``delete`` are the true effects (dynamic atoms) where given."""

    action: str
    args: list[str]
    add: list[str] | None = None
    delete: list[str] | None = None


class ObservedObject(_Model):
    """A perceived object: what a detector and depth camera would give."""

    id: str
    caption: str
    position: list[float] = Field(description="x, y, z of the base centre in metres (world frame)")
    size: list[float] = Field(description="extent x, y, z in metres")
    keypoints: list[str] = []


class SceneAbstractionInput(_Model):
    """Objects with positions and captions."""

    objects: list[ObservedObject]


class SceneAbstractionOutput(_Model):
    """The scene graph they form."""

    graph: SceneGraph


class NextActionInput(_Model):
    """Goal (instruction and PDDL), the current graph and the steps taken so far (with their effects)."""

    instruction: str
    goal: str
    graph: SceneGraph
    history: list[StepData]


class NextActionOutput(_Model):
    """The next step with its effects, or ``done`` when the goal holds."""

    done: bool
    step: StepData | None


class ForwardInput(_Model):
    """A graph and a step applied to it."""

    graph: SceneGraph
    step: StepData


class ForwardOutput(_Model):
    """The next graph and the atom-level change."""

    graph: SceneGraph
    add: list[str]
    delete: list[str]


class InverseInput(_Model):
    """Start and goal graphs."""

    start_graph: SceneGraph
    goal_graph: SceneGraph


class InverseOutput(_Model):
    """A validated plan from start to goal."""

    plan: list[StepData]


class GoalInput(_Model):
    """An instruction and the scene it refers to."""

    instruction: str
    graph: SceneGraph


class GoalOutput(_Model):
    """The goal as PDDL and as a partial goal graph (the nodes and relations the goal requires)."""

    goal: str
    goal_graph: SceneGraph


SCHEMAS: dict[str, tuple[type[_Model], type[_Model]]] = {
    "scene_abstraction": (SceneAbstractionInput, SceneAbstractionOutput),
    "next_action": (NextActionInput, NextActionOutput),
    "forward_prediction": (ForwardInput, ForwardOutput),
    "inverse_action": (InverseInput, InverseOutput),
    "goal_interpretation": (GoalInput, GoalOutput),
}


class SampleRow(_Model):
    """One JSONL row. ``input``/``output`` are JSON text (see :data:`SCHEMAS` for their shape per type)."""

    id: str
    type: Literal[
        "scene_abstraction", "next_action", "forward_prediction", "inverse_action", "goal_interpretation"
    ]
    split: Literal["train", "val", "test"]
    heldout: str = Field(description="'' for train/val; 'pair', 'color' or 'horizon' for test rows")
    task: str = Field(description="id of the planned task the row comes from (rows of one task share it)")
    horizon: int = Field(description="length of the task's validated plan")
    input: str
    output: str


def decode(row: dict[str, Any]) -> tuple[SampleRow, _Model, _Model]:
    """Validate a row and parse its ``input`` and ``output`` into the typed models of its type."""
    rid = row.get("id", "<row>") if isinstance(row, dict) else "<row>"
    try:
        envelope = SampleRow.model_validate(row)
        inp_model, out_model = SCHEMAS[envelope.type]
        return (
            envelope,
            inp_model.model_validate(json.loads(envelope.input)),
            out_model.model_validate(json.loads(envelope.output)),
        )
    except ValidationError as exc:
        raise GSRError(f"sample {rid}: {format_validation_error(exc)}") from None
    except json.JSONDecodeError as exc:
        raise GSRError(f"sample {rid}: input/output is not JSON: {exc.msg}") from None


def schemas_json() -> dict[str, Any]:
    """JSON Schemas of the envelope and of every type's input and output."""
    out: dict[str, Any] = {"version": SCHEMA_VERSION, "row": SampleRow.model_json_schema(), "types": {}}
    for name, (i, o) in SCHEMAS.items():
        out["types"][name] = {"input": i.model_json_schema(), "output": o.model_json_schema()}
    return out
