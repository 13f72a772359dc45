"""A Gymnasium environment over a task: observations are RGB-D plus the scene graph, actions are steps.

An action is one symbolic step, as text (``"(pick akita_black_bowl_1 main_table)"``) or a
``gsr.step.Step``; the environment checks it against the observed graph, runs the meta-skill, and
returns the new observation. Reward is 1 when the task's goal holds in the observed graph (episode
terminated), 0 otherwise; an invalid or failed step also terminates (``info["diagnosis"]`` says why).
"""

from __future__ import annotations

import string
from typing import Any, ClassVar

import numpy as np
from gsr.skills.build import build_world
from gsr.skills.camera import default_views, render
from gsr.skills.executor import PhysicalExecutor

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.plan_format import parse_plan
from gsr.semantics import goal_holds
from gsr.step import Step
from gsr.task_spec import TaskSpec

ACTION_CHARSET = string.ascii_lowercase + string.digits + "_-./() "
MAX_TEXT = 1 << 16


def _gym() -> Any:
    import gymnasium

    return gymnasium


def parse_action(action: str | Step) -> Step:
    """A step from an action: a ``Step`` as is, or text such as ``(pick cube_1 table)``."""
    if isinstance(action, Step):
        return action

    plan = parse_plan(str(action), source="action")
    if len(plan) != 1:
        raise GSRError(f"action {action!r}: expected exactly one step, got {len(plan)}")
    return plan.steps[0]


def make_env(task: TaskSpec, **kwargs: Any) -> Any:
    """A :class:`SkillEnv` for ``task`` (imports gymnasium lazily)."""
    return _env_class()(task, **kwargs)


def _env_class() -> type:
    gym = _gym()
    from gymnasium import spaces

    class SkillEnv(gym.Env):  # type: ignore[misc, name-defined]
        """Gymnasium env: observation {rgb, depth, graph (JSON)}, action = one step (text or Step)."""

        metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 4}

        def __init__(
            self,
            task: TaskSpec,
            camera: str = "front",
            width: int = 160,
            height: int = 120,
            max_steps: int = 30,
            render_mode: str | None = "rgb_array",
        ) -> None:
            self.task = task
            self.camera = camera
            self.width, self.height = width, height
            self.max_steps = max_steps
            self.render_mode = render_mode
            self.observation_space = spaces.Dict(
                {
                    "rgb": spaces.Box(0, 255, (height, width, 3), np.uint8),
                    "depth": spaces.Box(0.0, np.inf, (height, width), np.float32),
                    "graph": spaces.Text(MAX_TEXT, charset=string.printable),
                }
            )
            self.action_space = spaces.Text(256, charset=ACTION_CHARSET)
            self.world = None
            self.executor = None
            self.steps = 0

        def _spec(self):
            from dataclasses import replace

            return replace(default_views(self.world)[self.camera], width=self.width, height=self.height)

        def _obs(self) -> dict[str, Any]:
            img = render(self.world, self._spec())
            return {"rgb": img.rgb, "depth": img.depth, "graph": self.executor.graph.to_json(indent=None)}

        def _goal_met(self) -> bool:
            state = state_from_graph(self.executor.graph, self.executor.domain)
            return any(goal_holds(self.executor.domain, g, state) for g in self.task.goal_formulas())

        def reset(self, *, seed: int | None = None, options: dict | None = None):
            """Build the task's world (deterministic per seed) and observe it."""
            super().reset(seed=seed)

            if self.world is not None:
                self.world.close()
            self.world = build_world(self.task, seed if seed is not None else 0)
            self.executor = PhysicalExecutor(self.world)
            self.steps = 0
            return self._obs(), {"goal_met": self._goal_met()}

        def step(self, action: str | Step):
            """Check and execute one step; reward 1 and terminate when the goal holds."""
            if self.executor is None:
                raise GSRError("call reset() before step()")
            self.steps += 1
            try:
                step = parse_action(action)
            except GSRError as exc:
                return self._obs(), 0.0, True, False, {"diagnosis": str(exc), "goal_met": False}
            out = self.executor.step(step, self.steps)
            goal = self._goal_met()
            info = {"diagnosis": out.diagnosis, "goal_met": goal, "outcome": out.to_dict()}
            terminated = goal or not out.ok
            truncated = not terminated and self.steps >= self.max_steps
            return self._obs(), float(goal), terminated, truncated, info

        def render(self) -> np.ndarray:
            """The current RGB image from the env's camera."""
            return render(self.world, self._spec()).rgb

        def close(self) -> None:
            """Release the physics client."""
            if self.world is not None:
                self.world.close()
                self.world = None

    return SkillEnv
