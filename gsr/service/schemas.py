"""Request bodies of the reasoning API (pydantic; FastAPI turns them into the OpenAPI schema)."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field


class StepIn(BaseModel):
    """A step as JSON: the ground action and, optionally, the effects the reasoner claims."""

    model_config = ConfigDict(extra="forbid")
    action: str
    args: list[str] = Field(default_factory=list)
    add: list[str] | None = Field(
        default=None, description="claimed added atoms, e.g. '(in bowl_1 drawer_1)'"
    )
    delete: list[str] | None = Field(default=None, description="claimed deleted atoms")


class DomainRef(BaseModel):
    """Which domain: a built-in one by name (default ``tabletop``) or PDDL text."""

    model_config = ConfigDict(extra="forbid")
    domain: str = Field(default="tabletop", description="name of a built-in domain (GET /v1/domains)")
    domain_pddl: str | None = Field(default=None, description="a PDDL domain as text; overrides `domain`")


class CheckRequest(DomainRef):
    """POST /v1/check: one step against a scene graph (inline, or stored with POST /v1/scenes)."""

    scene_graph: dict[str, Any] | None = Field(
        default=None, description="scene-graph JSON or a GSR-Bench message {nodes, edges}"
    )
    scene_id: str | None = Field(default=None, description="a scene stored with POST /v1/scenes")
    step: str | StepIn = Field(description="'(pick red_cube1 table)' or a StepIn object")


class TaskIn(DomainRef):
    """A task: either a PDDL problem, or a scene graph with a goal formula."""

    problem_pddl: str | None = Field(default=None, description="a PDDL problem as text")
    scene_graph: dict[str, Any] | None = None
    scene_id: str | None = Field(default=None, description="a scene stored with POST /v1/scenes")
    goal: str | None = Field(default=None, description="PDDL goal formula over the graph's node ids")


class ValidateRequest(TaskIn):
    """POST /v1/validate: a plan against a task."""

    plan: str | list[str | StepIn] = Field(description="IPC plan text, or a list of steps")


class PlanRequest(TaskIn):
    """POST /v1/plan: plan a task."""

    planner: str = "lazy-ff"
    timeout: float | None = Field(default=None, gt=0, description="seconds; capped by the server's budget")


class GroundRequest(BaseModel):
    """POST /v1/ground: an instruction to a goal over a scene graph."""

    model_config = ConfigDict(extra="forbid")
    scene_graph: dict[str, Any]
    instruction: str = Field(min_length=1)


class SolveRequest(GroundRequest):
    """POST /v1/solve: instruction -> goal -> checked steps."""

    backend: str = Field(default="grounder", description="reasoner backend; the service offers 'grounder'")
    mode: str = Field(default="goal", description="steps | goal | hybrid")
    timeout: float | None = Field(default=None, gt=0)
