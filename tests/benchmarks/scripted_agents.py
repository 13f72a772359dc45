"""Scripted agents for the runner tests (importable by worker processes as module:factory)."""

from __future__ import annotations

from gsr.diagnosis import Diagnosis
from gsr.pddl.parser import parse_formula
from gsr.scene_graph import SceneGraph
from gsr.step import Step


class Scripted:
    """Replays fixed steps, then says done; ``believed`` is the goal it claims to pursue."""

    name = "scripted"

    def __init__(
        self, steps: list[list[str]] | None = None, believed: str | None = None, retry_with=None
    ) -> None:
        self.steps = [Step(s[0], tuple(s[1:])) for s in steps or []]
        self.believed_goal = parse_formula(believed) if believed else None
        self.retry_with = Step(retry_with[0], tuple(retry_with[1:])) if retry_with else None
        self.feedback: list[Diagnosis] = []

    def reset(self, task, domain, seed: int) -> None:
        self.queue = list(self.steps)

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        if feedback is not None and not feedback.ok:
            self.feedback.append(feedback)
            if self.retry_with is not None:
                step, self.retry_with = self.retry_with, None
                return step
        return self.queue.pop(0) if self.queue else None


def always_done(prompt_text: str) -> str:
    """A 'model' that always answers (done): the reasoner stops at once."""
    return "(done)"


def bad_step(prompt_text: str) -> str:
    """A 'model' that always proposes an impossible step."""
    return "(place_in red_cube box)"
