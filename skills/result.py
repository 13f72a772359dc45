"""Typed skill outcomes: success, or a failure kind with a message and what the simulator observed."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class Failure(StrEnum):
    """Why a skill failed."""

    UNREACHABLE = "unreachable"  # no inverse-kinematics solution for a required pose
    BLOCKED = "blocked"  # every candidate motion collides, or the arm was stopped by contact
    GRASP_MISSED = "grasp_missed"  # the fingers closed on nothing
    GRASP_SLIPPED = "grasp_slipped"  # the object fell out of the hand while moving
    TIMEOUT = "timeout"  # the step budget ran out before the motion converged
    IK_FLIP = "ik_flip"  # a straight path needs an IK branch flip (a wild joint jump): not executed
    NOT_ACHIEVED = "not_achieved"  # the motion ran, but the sim state is not the step's effect
    UNSUPPORTED = "unsupported"  # no physical counterpart for the action or its objects


class SkillError(Exception):
    """Raised inside a skill to stop it with a typed failure."""

    def __init__(self, failure: Failure, message: str) -> None:
        super().__init__(message)
        self.failure = failure
        self.message = message


@dataclass(frozen=True)
class SkillResult:
    """What one skill did: ``ok``, or the failure; simulation steps and wall time spent; observations."""

    skill: str
    step: str
    ok: bool
    failure: Failure | None = None
    message: str = ""
    sim_steps: int = 0
    wall_s: float = 0.0
    observed: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "skill": self.skill,
            "step": self.step,
            "ok": self.ok,
            "failure": self.failure.value if self.failure else None,
            "message": self.message,
            "sim_steps": self.sim_steps,
            "wall_s": round(self.wall_s, 3),
            "observed": self.observed,
        }
