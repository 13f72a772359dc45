"""The physical runner's executor: ``gsr.skills.SimExecutor`` with perceived graphs, saved frames and a truth verdict.

``RunnerSimExecutor`` implements ``gsr.episode.Executor``. With ``perceive=False`` it is the
simulator executor of ``skills`` (the agent observes the simulator's ground-truth graph). With
``perceive=True`` the agent's initial graph and the graph re-derived after every step come from
:class:`gsr.skills.perceived_scene.PerceivedScene` (cameras + perception, the known map, the gripper,
object permanence), and the closed loop compares the expected next graph with the perceived one only on
what the sensors confirm (:func:`gsr.skills.perceived_scene.observable_view`). Either way
:meth:`RunnerSimExecutor.truth_state` is the simulator's ground truth, which is what the runner scores:
physical success means the goal holds in the world, not in the agent's belief.
"""

from __future__ import annotations

import re
from typing import Any

from gsr.skills.build import build_world
from gsr.skills.executor import PhysicalExecutor
from gsr.skills.library import run_step
from gsr.skills.perceived_scene import VIEWS, PerceivedScene, observable_view, observed_ids
from gsr.skills.sim_executor import SimExecutor
from gsr.skills.sim_graph import scene_graph_from_sim

from gsr.facts import state_from_graph
from gsr.graph_diff import diff_graphs
from gsr.pddl.model import Domain
from gsr.state import State
from gsr.step import Step
from gsr.task_spec import TaskSpec


class PerceivingPhysicalExecutor(PhysicalExecutor):
    """``PhysicalExecutor`` whose observed graph is perceived (``PerceivedScene``) instead of read from the simulator."""

    observed_word = "perceived"
    divergence_word = "perception"

    def __init__(self, world: Any, domain: Domain, scene: PerceivedScene, keep_frames: bool = False) -> None:
        super().__init__(world, domain)  # its ground-truth initial graph is replaced just below
        self.scene = scene
        self.keep_frames = keep_frames
        self.graph = self._observe()

    def _observe(self, expected: Any = None) -> Any:
        graph = self.scene.observe(expected)
        if self.keep_frames and self.scene.last_rgb is not None:
            self.frames.append(self.scene.last_rgb)  # the perceived front view: no second rendering
        return graph

    def _act(self, step: Any) -> Any:
        """Run the skill on the bodies the step's perceived nodes are (:meth:`PerceivedScene.world_id`)."""
        acted = Step(step.action, tuple(self.scene.world_id(a) for a in step.args))
        return run_step(self.world, acted, self.budget)

    def _divergence(self, expected: Any) -> Any:
        """Compare only facts about nodes seen now *and* expected, and only what sensors confirm.

        An object that reappears (the arm had hidden it) or is seen for the first time is a discovery,
        not a contradiction of the step's effects.
        """
        confirmed = observed_ids(self.graph) & {n.id for n in expected.nodes}
        return diff_graphs(observable_view(expected, confirmed), observable_view(self.graph, confirmed))


class RunnerSimExecutor(SimExecutor):
    """The runner's physical executor: ground-truth or perceived observations, frames kept, truth scored."""

    def __init__(
        self,
        seed: int = 0,
        perceive: bool = False,
        frames: int = 0,
        views: tuple[str, ...] = VIEWS,
        oracle_masks: bool = False,
    ) -> None:
        # frames > 0: keep the first view's RGB after every step; SimExecutor.frames samples `frames` of them
        super().__init__(seed=seed, frame_camera=views[0] if frames else None, max_frames=max(frames, 1))
        self.perceive = perceive
        self.views = views
        self.oracle_masks = oracle_masks  # perceive from the simulator's labelled masks (the earlier path)

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """Build the task's world; the observed initial state (perceived when ``perceive``)."""
        if not self.perceive:
            return super().reset(task, domain)
        self.close()
        self.domain = domain
        world = build_world(task, seed=self.seed)
        try:
            scene = PerceivedScene(world, self.views, oracle_masks=self.oracle_masks)
            self.ex = PerceivingPhysicalExecutor(
                world, domain, scene, keep_frames=self.frame_camera is not None
            )
        except BaseException:
            world.close()
            raise
        self.outcomes = []
        return state_from_graph(self.ex.graph, domain)

    def agent_task(self, task: TaskSpec) -> TaskSpec:
        """The task as the agent may see it: with ``perceive``, the initial graph is the perceived one (not
        the task's), and the goal formula (which only the planner agent reads: "goal given") names the
        perceived nodes that are the goal's bodies (:attr:`PerceivedScene.binding`)."""
        if not self.perceive or not isinstance(self.ex, PerceivingPhysicalExecutor):
            return task
        scene = self.ex.scene
        back = {w: p for p, w in scene.binding.items()}
        return task.model_copy(
            update={
                "initial": self.ex.graph,
                "goal": rename_in_formula(task.goal, back),
                "goal_alternatives": tuple(rename_in_formula(g, back) for g in task.goal_alternatives),
            }
        )

    def truth_state(self) -> State:
        """The simulator's ground-truth state now (what physical success is judged on)."""
        assert self.ex is not None and self.domain is not None, "call reset() first"
        return state_from_graph(scene_graph_from_sim(self.ex.world), self.domain)

    def belief_state(self) -> State:
        """The agent's final observed state (perceived or ground truth), in the world's node ids (perceived
        nodes renamed to the bodies they are) so that the task's goal can be checked on it."""
        assert self.ex is not None and self.domain is not None, "call reset() first"
        graph = self.ex.graph
        if isinstance(self.ex, PerceivingPhysicalExecutor):
            graph = self.ex.scene.in_world_ids(graph)
        return state_from_graph(graph, self.domain)


_TOKEN = re.compile(r"[^\s()]+")


def rename_in_formula(text: str, mapping: dict[str, str]) -> str:
    """A PDDL formula's object names renamed by ``mapping`` (whole tokens only)."""
    return _TOKEN.sub(lambda m: mapping.get(m.group(0), m.group(0)), text)
