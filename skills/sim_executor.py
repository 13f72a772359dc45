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

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from gsr.skills.build import build_world
from gsr.skills.executor import PhysicalExecutor
from gsr.skills.recovery import MAX_CLEARANCES, blockers, keep_clear_around, set_aside, support_step
from gsr.skills.result import Failure

from gsr.check import check_step
from gsr.diagnosis import Diagnosis
from gsr.facts import state_from_graph
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.task_spec import TaskSpec

if TYPE_CHECKING:
    from gsr.skills.executor import StepOutcome


#: Skill failures raised by planning before anything moved (deterministic for a given scene).
REFUSALS = frozenset({Failure.BLOCKED, Failure.UNREACHABLE})


class SimExecutor:
    """A physical executor for the episode runner (one world per episode, closed after the next reset)."""

    def __init__(
        self,
        seed: int = 0,
        frame_camera: str | None = "front",
        max_frames: int = 4,
        clear_blockers: bool = True,
        max_episode_clearances: int = 6,
    ) -> None:
        self.seed = seed
        # a pick refused by movable neighbours in the hand's way sets them aside and tries again
        # (gsr.skills.recovery): at most MAX_CLEARANCES per step and ``max_episode_clearances`` per episode
        self.clear_blockers = clear_blockers
        self.max_episode_clearances = max_episode_clearances
        self.clearances = 0
        self.recoveries: list[dict] = []
        self.frame_camera = frame_camera
        self.max_frames = max_frames
        self.domain: Domain | None = None
        self.ex: PhysicalExecutor | None = None
        self.outcomes: list[StepOutcome] = []
        # (step, state fingerprint) -> outcome of a step refused by the motion planner (blocked or
        # unreachable before anything moved): the same step in the same state is not planned again
        self._refused: dict[tuple[str, tuple], StepOutcome] = {}

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """Build the task's world (deterministic per ``seed``); the observed initial state."""
        self.close()
        self.domain = domain
        world = build_world(task, seed=self.seed)
        self.ex = PhysicalExecutor(world, domain, frame_camera=self.frame_camera)
        self.outcomes = []
        self._refused = {}
        self.clearances = 0
        self.recoveries = []
        return state_from_graph(self.ex.graph, domain)

    def execute(self, step: Step) -> Diagnosis:
        """Check the step on the observed state, run its skill, and report what the simulator shows."""
        assert self.ex is not None and self.domain is not None, "call reset() first"
        checked = check_step(self.domain, state_from_graph(self.ex.graph, self.domain), step)
        if not checked.ok:
            return checked
        key = (str(step), self._fingerprint())
        if key in self._refused:
            # planning is deterministic for a given scene: replaying it costs the episode's time only
            before = self._refused[key]
            out = replace(
                before,
                index=len(self.outcomes) + 1,
                diagnosis=f"{before.diagnosis} (not planned again: the scene is as it was when it was refused)",
            )
        else:
            out = self.ex.step(step, len(self.outcomes) + 1)
            if out.skill is not None and out.skill.failure in REFUSALS:
                self._refused[(str(step), self._fingerprint())] = out
        self.outcomes.append(out)
        if out.ok:
            return checked
        cleared = self._clear_and_retry(step, out, checked)
        if cleared is not None:
            return cleared
        return Diagnosis(
            ok=False,
            step=step,
            message=f"physical execution failed: {out.diagnosis}",
            hints=("the scene graph now shows what the simulator observed; replan from it",),
        )

    def _clear_and_retry(self, step: Step, out: StepOutcome, checked: Diagnosis) -> Diagnosis | None:
        """A pick refused because movable neighbours were in the hand's way: set at most
        :data:`~gsr.skills.recovery.MAX_CLEARANCES` of them aside on the table (checked steps of their
        own) and pick again. None when nothing was set aside; else a diagnosis that says what moved: ok
        (with the step's own transition) when the pick then succeeded, else not ok; either way the
        observed graph differs from the agent's plan, which should be planned again from it."""
        assert self.ex is not None
        ex = self.ex
        if (
            not self.clear_blockers
            or step.action != "pick"
            or out.skill is None
            or out.skill.failure is not Failure.BLOCKED
            or type(ex)._act is not PhysicalExecutor._act  # steps name the world's objects
            or self.clearances >= self.max_episode_clearances
        ):
            return None
        target = step.args[0]
        moved: list[str] = []
        refused: list[str] = []  # neighbours whose own pick the motion planner refused (nothing moved)
        # what a refused neighbour's own pick named in its way (a cube packed behind a cube): set aside
        # first, after which that neighbour is tried again (refused -> deeper -> neighbour)
        deeper: dict[str, str] = {}
        notes: list[str] = []
        while len(moved) < MAX_CLEARANCES:
            named = [*deeper, *blockers(out.diagnosis, ex.world, ex.graph)]
            names = [n for n in dict.fromkeys(named) if n not in moved and n not in refused and n != target]
            if not names or self.clearances >= self.max_episode_clearances:
                break
            node = names[0]
            lift = support_step(ex.graph, node)
            if lift is None:
                break
            self.clearances += 1
            taken = ex.step(lift, len(self.outcomes) + 1)
            self.outcomes.append(taken)
            if taken.skill is None:  # the checker rejected the pick: nothing moved
                break
            if not taken.ok and taken.skill.failure in REFUSALS:
                # packed in as the object is (a mug by a box's end wall): the next one named, if any;
                # what its own refusal names in its way comes first
                refused.append(node)
                notes.append(f"{node} could not be taken: {taken.skill.message}")
                for n in blockers(taken.diagnosis, ex.world, ex.graph):
                    if n not in moved and n != target and n != node:
                        deeper.setdefault(n, node)
                continue
            moved.append(node)
            if node in deeper and deeper[node] in refused:
                refused.remove(deeper.pop(node))  # its blocker is being moved: it may be taken now
            deeper.pop(node, None)
            if not taken.ok:
                notes.append(f"setting {node} aside failed: {taken.diagnosis}")
                break
            keep = keep_clear_around(ex.world, target)
            down = Step("place_on", (node, ex.world.table_id))
            put = ex.step(
                down, len(self.outcomes) + 1, act=lambda n=node, k=keep: set_aside(ex.world, n, k, ex.budget)
            )
            self.outcomes.append(put)
            if not put.ok:
                notes.append(f"setting {node} aside failed: {put.diagnosis}")
                break
            notes.append(f"set {node} aside on {ex.world.table_id}")
            out = ex.step(step, len(self.outcomes) + 1)
            self.outcomes.append(out)
            if out.ok:
                notes.append(f"{step} then succeeded")
                break
            notes.append(f"{step} refused again: {out.skill.message if out.skill else out.diagnosis}")
            if out.skill is None or out.skill.failure is not Failure.BLOCKED:
                break
        if not moved:
            return None  # (refused neighbours: the scene is as it was, the step's own failure stands)
        self.recoveries.append({"step": str(step), "moved": moved, "picked": out.ok, "notes": notes})
        if out.ok:
            # the pick went through once the neighbours moved: the step is done (not a rejection the
            # episode's retry budget pays for) with its own transition; the graph shows the moved
            # neighbours besides, so a closed-loop agent sees it is not in the state the step leads to
            # and plans again from it
            return replace(
                checked,
                message=f"executed after a clearance: {step}: " + "; ".join(notes),
                hints=("neighbours were moved: the scene graph shows where; replan from it",),
            )
        return Diagnosis(
            ok=False,
            step=step,
            message=f"physical execution: clearance for {step}: " + "; ".join(notes),
            hints=("neighbours were moved: the scene graph shows where; replan from it",),
        )

    def _fingerprint(self) -> tuple:
        """The scene as far as motion planning sees it: every object's pose to 5 mm / 0.05 rad and
        every articulated part's joint position to 5 mm (or 0.05 rad)."""
        import pybullet as p

        assert self.ex is not None
        w = self.ex.world
        out = []
        for o in sorted(w.objects.values(), key=lambda o: o.id):
            pos, quat = p.getBasePositionAndOrientation(o.body, physicsClientId=w.client)
            yaw = p.getEulerFromQuaternion(quat)[2]
            joints = tuple(
                round(p.getJointState(o.body, j, physicsClientId=w.client)[0] / 0.005)
                for j in range(p.getNumJoints(o.body, physicsClientId=w.client))
            )
            out.append((o.id, *(round(v / 0.005) for v in pos), round(yaw / 0.05), joints))
        return tuple(out)

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
