"""What a reasoner run returns: the goal, the checked steps with diagnoses, the transcript, the counts."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from gsr.diagnosis import Diagnosis, formula_text
from gsr.reason.examples import claimed_effects
from gsr.reason.options import Status
from gsr.reason.prompt import Prompt
from gsr.reason.step_format import format_step
from gsr.scene_graph import SceneGraph
from gsr.step import Goal, Plan, Step

#: Run outcomes as strings (the members of :class:`Status`); only ``solved`` is a success.
STATUSES = tuple(s.value for s in Status)


@dataclass(frozen=True)
class Attempt:
    """One model answer: the reply text, the parsed step (if any) and why it was rejected (if it was)."""

    reply: str
    step: Step | None = None
    diagnosis: Diagnosis | None = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        """True when the answer was accepted."""
        return self.error is None and (self.diagnosis is None or self.diagnosis.ok)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form."""
        out: dict[str, Any] = {"reply": self.reply, "ok": self.ok}
        if self.step is not None:
            out["step"] = format_step(self.step)
        if self.diagnosis is not None:
            out["diagnosis"] = self.diagnosis.to_dict()
        if self.error is not None:
            out["error"] = self.error
        return out


@dataclass(frozen=True)
class CheckedStep:
    """An executed step: the step, the checker's verdict, who proposed it and the answers rejected before it."""

    step: Step
    diagnosis: Diagnosis
    source: str  # "model" | "planner"
    rejected: tuple[Attempt, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form."""
        change = {}
        if self.diagnosis.transition is not None:  # the change the step made (what a claim must say)
            true = claimed_effects(self.diagnosis, self.diagnosis.transition[0])
            change = {"add": [str(a) for a in true.add or ()], "delete": [str(a) for a in true.delete or ()]}
        return {
            "step": format_step(self.step),
            "source": self.source,
            "effects": change,
            "rejected": [a.to_dict() for a in self.rejected],
        }


@dataclass(frozen=True)
class Exchange:
    """One model call: what was asked (kind and prompt), the answer and how long it took."""

    kind: str
    prompt: Prompt
    response: str
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form (the prompt as chat messages)."""
        return {
            "kind": self.kind,
            "messages": self.prompt.messages(),
            "response": self.response,
            "seconds": round(self.seconds, 4),
        }


@dataclass
class ReasonResult:
    """The outcome of :func:`gsr.reason.solve`."""

    instruction: str
    mode: str
    backend: str
    goal: Goal | None = None
    goal_source: str | None = None  # "given" | "grounder" | "model"
    steps: list[CheckedStep] = field(default_factory=list)
    goal_attempts: list[Attempt] = field(default_factory=list)
    transcript: list[Exchange] = field(default_factory=list)
    status: Status = Status.STEP_LIMIT
    message: str = ""
    final_graph: SceneGraph | None = None
    planner_takeovers: int = 0
    seconds: float = 0.0
    # answers rejected for a step that was never accepted (the run stopped or the planner took over)
    unrepaired: list[tuple[Attempt, ...]] = field(default_factory=list)

    @property
    def success(self) -> bool:
        """True when the goal is known and holds after the checked steps."""
        return self.status == Status.SOLVED

    @property
    def plan(self) -> Plan:
        """The executed steps as a plan."""
        return Plan(tuple(s.step for s in self.steps))

    @property
    def rejections(self) -> int:
        """Model answers rejected (parse errors, invalid steps, wrong effects, bad goals)."""
        return (
            sum(len(s.rejected) for s in self.steps)
            + sum(not a.ok for a in self.goal_attempts)
            + sum(len(a) for a in self.unrepaired)
        )

    @property
    def repairs(self) -> int:
        """Steps (and goals) accepted after at least one rejected answer: successful repairs."""
        goal_repaired = bool(self.goal_attempts) and self.goal_attempts[-1].ok and len(self.goal_attempts) > 1
        return sum(1 for s in self.steps if s.rejected and s.source == "model") + int(goal_repaired)

    @property
    def model_calls(self) -> int:
        """Number of backend calls."""
        return len(self.transcript)

    def to_dict(self, transcript: bool = False) -> dict[str, Any]:
        """JSON-friendly summary; ``transcript=True`` includes every prompt and response."""
        out: dict[str, Any] = {
            "instruction": self.instruction,
            "mode": self.mode,
            "backend": self.backend,
            "status": str(self.status),
            "success": self.success,
            "message": self.message,
            "goal": None if self.goal is None else formula_text(self.goal.formula),
            "goal_source": self.goal_source,
            "steps": [s.to_dict() for s in self.steps],
            "goal_attempts": [a.to_dict() for a in self.goal_attempts],
            "unrepaired": [[a.to_dict() for a in group] for group in self.unrepaired],
            "counts": {
                "steps": len(self.steps),
                "model_steps": sum(s.source == "model" for s in self.steps),
                "planner_steps": sum(s.source == "planner" for s in self.steps),
                "rejections": self.rejections,
                "repairs": self.repairs,
                "planner_takeovers": self.planner_takeovers,
                "model_calls": self.model_calls,
            },
            "seconds": round(self.seconds, 4),
        }
        if transcript:
            out["transcript"] = [e.to_dict() for e in self.transcript]
        return out
