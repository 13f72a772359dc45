"""The benchmark runner's executor seam, physically: ``reset`` builds the world, ``execute`` runs a step.

``SimExecutor`` implements the core's episode seam :class:`gsr.episode.Executor`
(``reset(task, domain) -> State``, ``execute(step) -> Diagnosis``, ``graph() -> SceneGraph``) over
:class:`gsr.skills.executor.PhysicalExecutor`: a step is first checked on the *observed* state (an
invalid step moves nothing), then executed by its meta-skill; a skill failure or a divergence between
the expected and the observed graph comes back as a non-ok ``Diagnosis`` whose message says what
happened, and ``graph()`` is always what the simulator shows, so an agent that gets feedback replans
from reality.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gsr.diagnosis import Diagnosis
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.task_spec import TaskSpec

if TYPE_CHECKING:
    from gsr.skills.executor import PhysicalExecutor, StepOutcome


class SimExecutor:
    """A physical executor for the episode runner (one world per episode, closed after the next reset)."""

    def __init__(self, seed: int = 0, frame_camera: str | None = "front", max_frames: int = 4) -> None:
        self.seed = seed
        self.frame_camera = frame_camera
        self.max_frames = max_frames
        self.domain: Domain | None = None
        self.ex: PhysicalExecutor | None = None
        self.outcomes: list[StepOutcome] = []

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """Build the task's world (deterministic per ``seed``); the observed initial state."""
        from gsr.skills.executor import PhysicalExecutor
        from gsr.skills.world import build_world

        from gsr.facts import state_from_graph

        self.close()
        self.domain = domain
        world = build_world(task, seed=self.seed)
        self.ex = PhysicalExecutor(world, domain, frame_camera=self.frame_camera)
        self.outcomes = []
        return state_from_graph(self.ex.graph, domain)

    def execute(self, step: Step) -> Diagnosis:
        """Check the step on the observed state, run its skill, and report what the simulator shows."""
        from gsr.check import check_step
        from gsr.facts import state_from_graph

        assert self.ex is not None and self.domain is not None, "call reset() first"
        checked = check_step(self.domain, state_from_graph(self.ex.graph, self.domain), step)
        if not checked.ok:
            return checked
        out = self.ex.step(step, len(self.outcomes) + 1)
        self.outcomes.append(out)
        if out.ok:
            return checked
        return Diagnosis(
            ok=False,
            step=step,
            message=f"physical execution failed: {out.diagnosis}",
            hints=("the scene graph now shows what the simulator observed; replan from it",),
        )

    def graph(self) -> SceneGraph:
        """The observed scene graph (ground truth from the simulator)."""
        assert self.ex is not None, "call reset() first"
        return self.ex.graph

    @property
    def frames(self) -> list[np.ndarray]:
        """Up to ``max_frames`` RGB frames of the episode: the first, evenly spaced ones, the last."""
        frames = self.ex.frames if self.ex is not None else []
        if len(frames) <= self.max_frames:
            return list(frames)
        idx = np.linspace(0, len(frames) - 1, self.max_frames).round().astype(int)
        return [frames[i] for i in idx]

    def close(self) -> None:
        """Release the physics client of the current episode."""
        if self.ex is not None:
            self.ex.world.close()
            self.ex = None
