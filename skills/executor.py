"""Closed-loop plan execution: run each checked step physically, re-derive the graph, compare, stop on divergence.

Before a step runs, the symbolic transition of the *observed* graph gives the expected next graph
(``gsr.transition.apply_step``); if the checker rejects the step there, execution stops before moving.
After the skill, :func:`gsr.skills.sim_graph.scene_graph_from_sim` gives the observed graph; its symbolic
part (support edges, open/on/held states) is diffed against the expectation (``gsr.graph_diff``). Any
difference, or a skill failure, stops execution with a diagnosis, so a reasoner can replan from the
observed graph (``ExecutionResult.final_graph``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from gsr.skills.camera import default_views, render
from gsr.skills.library import DEFAULT_BUDGET, run_step
from gsr.skills.result import SkillResult
from gsr.skills.sim_graph import scene_graph_from_sim
from gsr.skills.world import World

from gsr.graph_diff import GraphDiff, diff_graphs
from gsr.pddl.model import Domain
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.step import Plan, Step
from gsr.transition import StepRejected, apply_step

#: Node states that belong to the symbolic state (the rest is description).
SYMBOLIC_STATES = frozenset({"open", "on", "held"})


def symbolic_view(graph: SceneGraph) -> SceneGraph:
    """The graph's symbolic part only: support edges and open/on/held states, no geometry."""
    nodes = tuple(
        n.model_copy(
            update={
                "states": tuple(s for s in n.states if s in SYMBOLIC_STATES),
                "pose": None,
                "bbox": None,
                "keypoints": (),
            }
        )
        for n in graph.nodes
    )
    edges = tuple(e for e in graph.edges if e.relation in ("on", "in"))
    return SceneGraph(nodes=nodes, edges=edges)


@dataclass(frozen=True)
class StepOutcome:
    """One executed step: the skill's result and how the observed graph compares with the expected one."""

    index: int
    step: str
    skill: SkillResult | None
    diff: GraphDiff | None  # expected -> observed (empty when they agree)
    diagnosis: str = ""

    @property
    def ok(self) -> bool:
        """The skill succeeded and the observed graph is the expected one."""
        return self.skill is not None and self.skill.ok and self.diff is not None and self.diff.is_empty

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "index": self.index,
            "step": self.step,
            "ok": self.ok,
            "skill": self.skill.to_dict() if self.skill else None,
            "diff": self.diff.to_dict() if self.diff else None,
            "diagnosis": self.diagnosis,
        }


@dataclass
class ExecutionResult:
    """What executing a plan did: per-step outcomes, the final observed graph and why it stopped."""

    ok: bool
    steps: list[StepOutcome]
    final_graph: SceneGraph
    diagnosis: str = ""
    failed_step: int | None = None
    wall_s: float = 0.0
    sim_steps: int = 0
    frames: list[np.ndarray] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (frames and the final graph left out; see ``final_graph``)."""
        return {
            "ok": self.ok,
            "diagnosis": self.diagnosis,
            "failed_step": self.failed_step,
            "wall_s": round(self.wall_s, 3),
            "sim_steps": self.sim_steps,
            "steps": [s.to_dict() for s in self.steps],
        }


class PhysicalExecutor:
    """Executes steps in one world, closed loop; keeps the observed graph between steps."""

    def __init__(
        self,
        world: World,
        domain: Domain | None = None,
        budget: int = DEFAULT_BUDGET,
        frame_camera: str | None = None,
    ) -> None:
        self.world = world
        self.domain = domain or load_builtin_domain("tabletop")
        self.budget = budget
        self.frame_camera = frame_camera  # a default_views() name: save an RGB frame after each step
        self.graph = scene_graph_from_sim(world)
        self.frames: list[np.ndarray] = []
        if frame_camera:
            self._frame()

    def _frame(self) -> None:
        assert self.frame_camera is not None
        self.frames.append(render(self.world, default_views(self.world)[self.frame_camera]).rgb)

    # what the closed loop calls the graph it observes and the world it compares with (subclasses that
    # perceive instead of reading the simulator say "perceived" / "perception")
    observed_word = "observed"
    divergence_word = "reality"

    def _observe(self, expected: SceneGraph | None = None) -> SceneGraph:
        """The graph observed after a step: the simulator's ground truth (and a frame when asked)."""
        graph = scene_graph_from_sim(self.world)
        if self.frame_camera:
            self._frame()
        return graph

    def _divergence(self, expected: SceneGraph) -> GraphDiff:
        """What the observed graph contradicts of the expected one (symbolic facts only)."""
        return diff_graphs(symbolic_view(expected), symbolic_view(self.graph))

    def _act(self, step: Step) -> SkillResult:
        """Run the step's skill in the world (a perceiving subclass first resolves its node ids to bodies)."""
        return run_step(self.world, step, self.budget)

    def step(self, step: Step, index: int = 1, act: Callable[[], SkillResult] | None = None) -> StepOutcome:
        """Execute one step: check it on the observed graph, run the skill, observe, compare.

        ``act`` runs the step's skill instead of the library's (a recovery sets an object aside on a
        table spot it chooses); the step is checked and its outcome compared all the same."""
        name = str(step)
        try:
            expected = apply_step(self.graph, step, self.domain)
        except StepRejected as exc:
            return StepOutcome(
                index,
                name,
                None,
                None,
                f"step {index} {name} is invalid in the {self.observed_word} state: {exc}",
            )
        result = act() if act is not None else self._act(step)
        self.graph = self._observe(expected)
        diff = self._divergence(expected)
        why = ""
        if not result.ok:
            failure = result.failure.value if result.failure else "?"
            why = f"step {index} {name}: skill {result.skill} failed ({failure}): {result.message}"
        if not diff.is_empty:
            delta = str(diff).replace("\n", "; ")
            why = (
                why + "; " if why else f"step {index} {name}: "
            ) + f"{self.divergence_word} diverges from the expected graph: {delta}"
        return StepOutcome(index, name, result, diff, why)

    def execute(self, plan: Plan | Iterable[Step]) -> ExecutionResult:
        """Run the steps in order; stop at the first failure or divergence."""
        t0 = time.perf_counter()
        start_steps = self.world.sim_steps
        outcomes: list[StepOutcome] = []
        for i, step in enumerate(plan, 1):
            out = self.step(step, i)
            outcomes.append(out)
            if not out.ok:
                return ExecutionResult(
                    False,
                    outcomes,
                    self.graph,
                    out.diagnosis,
                    i,
                    time.perf_counter() - t0,
                    self.world.sim_steps - start_steps,
                    list(self.frames),
                )
        return ExecutionResult(
            True,
            outcomes,
            self.graph,
            "",
            None,
            time.perf_counter() - t0,
            self.world.sim_steps - start_steps,
            list(self.frames),
        )


def execute_plan(world: World, plan: Plan | Iterable[Step], **kwargs: Any) -> ExecutionResult:
    """Execute a checked plan physically in ``world`` (closed loop); see :class:`PhysicalExecutor`."""
    return PhysicalExecutor(world, **kwargs).execute(plan)
