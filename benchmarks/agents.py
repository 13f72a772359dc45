"""Agents under evaluation: the built-ins (planner, grounder, reasoner, random) of the core's ``Agent`` protocol.

An agent is reset on a task, then asked again and again for the next step given the current scene
graph and the instruction; it answers a :class:`~gsr.step.Step` or ``None`` ("done"). When the checker
rejects a step, the runner may ask again with the diagnosis as ``feedback``. To benchmark your own
agent, implement :class:`gsr.episode.Agent` (``name``, ``reset``, ``act``) and pass
``--agent package.module:factory`` (a class or a function returning an agent; keyword options come
from ``--agent-opt key=value``).
"""

from __future__ import annotations

import importlib
import random
from collections import deque
from collections.abc import Callable
from typing import Any

from gsr.benchmarks.scoring import any_goal

from gsr.diagnosis import Diagnosis
from gsr.episode import Agent, AgentFailure
from gsr.errors import GSRError
from gsr.facts import problem_from_graph, state_from_graph
from gsr.pddl.model import TRUE, Domain, Formula
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.plan.grounding import ground_task
from gsr.reason import Reasoner, SolveOptions
from gsr.scene_graph import SceneGraph
from gsr.step import Step
from gsr.task_spec import TaskSpec


class _PlanningAgent:
    """Shared logic: plan to a goal formula once, then replay the plan step by step; plan again from the
    shown graph after a rejected step, or after an accepted one when the graph's state is not the one the
    step leads to (an executor that also moved other objects, e.g. neighbours set aside for a pick)."""

    name = "planning"

    def __init__(self, planner: str = "lazy-ff", timeout: float = 60.0) -> None:
        self.planner = planner
        self.timeout = float(timeout)
        self.domain: Domain | None = None
        self.goal: Formula | None = None
        self.queue: deque[Step] = deque()
        self.plan_time = 0.0

    def _plan(self, graph: SceneGraph) -> None:
        assert self.domain is not None and self.goal is not None
        result = plan_api.plan_graph(
            self.domain, graph, self.goal, planner=self.planner, timeout=self.timeout
        )
        self.plan_time += result.time
        if not result.solved or result.plan is None:
            raise AgentFailure(f"planner {result.planner}: {result.status}: {result.message}")
        self.queue = deque(result.plan.steps)

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        """Next planned step; plans again from ``graph`` after a rejected step or when ``graph`` is not in
        the state the accepted step leads to."""
        if feedback is not None and (not feedback.ok or self._moved_otherwise(graph, feedback)):
            self._plan(graph)
        return self.queue.popleft() if self.queue else None

    def _moved_otherwise(self, graph: SceneGraph, feedback: Diagnosis) -> bool:
        """Whether the shown graph differs from the state the accepted step leads to."""
        expected = feedback.next_state
        if expected is None or self.domain is None:
            return False
        return state_from_graph(graph, self.domain).atoms != expected.atoms

    @property
    def believed_goal(self) -> Formula | None:
        """The goal this agent pursues (for the goal-error outcome class)."""
        return self.goal


class PlannerAgent(_PlanningAgent):
    """Oracle upper bound: the task's goal (any alternative), then the symbolic planner."""

    name = "planner"

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Plan from the initial graph to the task's goal."""
        self.domain, self.goal, self.plan_time = domain, any_goal(task), 0.0
        self._plan(task.initial)


class GrounderAgent(_PlanningAgent):
    """Instruction only: ``gsr.language.ground`` turns it into a goal, then the planner."""

    name = "grounder"

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Ground the instruction on the initial graph, then plan."""
        try:
            language = importlib.import_module("gsr.language")
            ground = language.ground
        except (ImportError, AttributeError):
            raise AgentFailure("gsr.language.ground is not available in this installation") from None
        self.domain, self.plan_time = domain, 0.0
        try:
            result = ground(task.instruction, task.initial, domain=domain)
        except GSRError as exc:
            raise AgentFailure(f"grounding failed: {exc}") from None
        formula = getattr(result, "formula", result)
        formula = getattr(formula, "formula", formula)
        if not isinstance(formula, Formula):
            raise AgentFailure(f"gsr.language.ground returned {type(result).__name__}, not a goal")
        self.goal = formula
        self._plan(task.initial)


class ReasonerAgent:
    """The LLM reasoner (:class:`gsr.reason.Reasoner`: propose, check, repair) as a closed-loop agent.

    ``reset`` solves once from the initial graph; ``act`` follows those checked steps while the graph
    it is shown is the one they predict, and plans again from the shown graph (towards the same goal)
    when it is not (a skill failed, perception saw something else) or when the last step was rejected.
    ``backend`` is a gsr.reason backend spec (``grounder``, ``transformers:PATH``, ``openai:MODEL``), a
    ``package.module:attr`` naming your own backend object or ``prompt text -> answer`` function, or such
    an object itself. The reasoner's rejected answers count as proposed-but-invalid steps.
    """

    name = "reasoner"

    def __init__(
        self,
        backend: Any = "grounder",
        mode: str = "steps",
        max_repairs: int = 3,
        constrained: bool = False,
        max_steps: int = 200,
        planner_timeout: float = 30.0,
    ) -> None:
        self.backend = _backend(backend)
        self.options = SolveOptions(
            mode=mode,
            max_repairs=int(max_repairs),
            constrained=bool(constrained),
            max_steps=int(max_steps),
            planner_timeout=float(planner_timeout),
        )
        self.reasoner: Any = None
        self.believed_goal: Formula | None = None
        self.status = ""

    @property
    def rejected_proposals(self) -> int:
        """Answers the reasoner rejected inside its solves this episode (they never reach the runner)."""
        return self.reasoner.rejections if self.reasoner is not None else 0

    @property
    def replans(self) -> int:
        """How often this episode planned again from the shown graph."""
        return self.reasoner.replans if self.reasoner is not None else 0

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Run the reasoner on the initial graph and instruction; its checked steps are the plan."""
        self.reasoner = Reasoner(self.backend, domain, self.options)
        result = self.reasoner.reset(task.initial, task.instruction)
        self.believed_goal = result.goal.formula if result.goal is not None else None
        self.status = str(result.status)
        if not result.steps and not result.success:
            raise AgentFailure(f"reasoner {result.status}: {result.message}")

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        """The next checked step for ``graph`` (None when the reasoner has nothing left to do)."""
        if self.reasoner is None:
            raise AgentFailure("the reasoner agent was not reset")
        replans = self.reasoner.replans
        step = self.reasoner.step(graph, feedback)
        if self.reasoner.replans != replans:
            last = self.reasoner.last
            self.status = str(last.status)
            if step is None and not last.success:
                raise AgentFailure(f"reasoner {last.status} after re-planning: {last.message}")
        return step


def _backend(spec: Any) -> Any:
    """A reasoner backend from a spec string, ``module:attr`` or an object."""
    if not isinstance(spec, str):
        return spec
    kind = spec.partition(":")[0]
    if spec == "grounder" or kind in ("transformers", "openai"):
        return spec
    if ":" in spec:
        module_name, _, attr = spec.partition(":")
        try:
            return getattr(importlib.import_module(module_name), attr)
        except (ImportError, AttributeError) as exc:
            raise GSRError(f"reasoner backend {spec!r}: cannot import: {exc}") from None
    raise GSRError(f"reasoner backend {spec!r}: use grounder, transformers:PATH, openai:MODEL or module:attr")


class RandomAgent:
    """The floor: uniformly random applicable steps, blind to the goal; says done with ``stop`` chance per step.

    The expected episode length is ``1 / stop`` steps (20 by default); success only happens when the
    random walk ends in a goal state.
    """

    name = "random"

    def __init__(self, stop: float = 0.05) -> None:
        if not 0.0 < float(stop) <= 1.0:
            raise GSRError(f"random agent: stop must be in (0, 1], got {stop}")
        self.stop = float(stop)
        self.rng = random.Random(0)
        self.task: Any = None
        self.state = 0

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Ground the scene's actions (the goal is not used) and seed the choices."""
        self.rng = random.Random(seed)
        self.task = ground_task(domain, problem_from_graph(task.initial, TRUE, domain=domain))
        self.state = self.task.init

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        """A random applicable ground action, or None (done) with probability ``stop``."""
        ops = self.task.applicable(self.state)
        if not ops or self.rng.random() < self.stop:
            return None
        op = self.rng.choice(ops)
        self.state = self.task.apply(self.state, op)
        g = self.task.ops[op]
        return Step(g.name, g.args)


BUILTIN: dict[str, Callable[..., Agent]] = {
    "planner": PlannerAgent,
    "grounder": GrounderAgent,
    "reasoner": ReasonerAgent,
    "random": RandomAgent,
}


def make_agent(spec: str, options: dict[str, Any] | None = None) -> Agent:
    """An agent from a built-in name or ``package.module:factory``, with keyword options."""
    options = dict(options or {})
    if spec in BUILTIN:
        factory = BUILTIN[spec]
    elif ":" in spec:
        module_name, _, attr = spec.partition(":")
        try:
            factory = getattr(importlib.import_module(module_name), attr)
        except (ImportError, AttributeError) as exc:
            raise GSRError(f"agent {spec!r}: cannot import: {exc}") from None
    else:
        raise GSRError(
            f"unknown agent {spec!r}; choose one of {', '.join(BUILTIN)} or package.module:factory"
        )
    try:
        agent = factory(**options)
    except TypeError as exc:
        raise GSRError(f"agent {spec!r}: bad options {options}: {exc}") from None
    if not isinstance(agent, Agent):
        raise GSRError(f"agent {spec!r}: {type(agent).__name__} lacks reset()/act()/name")
    return agent
