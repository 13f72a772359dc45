"""The reasoner's entry points: :func:`solve` (one run) and :class:`Reasoner` (a closed loop).

``Reasoner`` binds a backend, a domain and :class:`~gsr.reason.options.SolveOptions`: ``solve`` runs
one episode with :class:`~gsr.reason.loop.SolveLoop`; ``reset`` then ``step(graph, feedback)`` serve a
closed loop (a benchmark agent on the perceived scene), re-planning when the observed graph is not the
one the plan expected or a step was rejected.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence

from gsr.diagnosis import Diagnosis
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.pddl.model import Domain
from gsr.reason.backend import Backend
from gsr.reason.backends import as_backend
from gsr.reason.examples import Example
from gsr.reason.loop import SolveLoop
from gsr.reason.options import SolveOptions
from gsr.reason.result import ReasonResult
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.step import Goal, Step


class Reasoner:
    """A backend, a domain and :class:`SolveOptions` bound together.

    ``solve(graph, instruction)`` runs one episode to its end. For a closed loop (an agent whose steps
    are executed elsewhere, and which sees the scene again before each step), ``reset(graph,
    instruction)`` plans once and ``step(graph, feedback)`` returns the next checked step: the plan is
    followed while the observed graph is the one it predicts; when the graph differs (a skill failed,
    perception saw something else) or ``feedback`` rejects the last step, the reasoner plans again from
    the observed graph towards the same goal.
    """

    def __init__(
        self,
        backend: Backend | Callable[[str], str] | str = "grounder",
        domain: Domain | None = None,
        options: SolveOptions | None = None,
    ) -> None:
        self.backend = as_backend(backend)
        self.domain = domain or load_builtin_domain()
        self.options = options or SolveOptions()
        self.instruction = ""
        self.goal: Goal | None = None
        self.last: ReasonResult | None = None  # the latest solve (reset or re-plan)
        self.replans = 0
        self.rejections = 0  # answers rejected inside every solve since reset
        self._plan: deque[tuple[Step, frozenset]] = deque()  # steps with the state each one leads to
        self._expected: frozenset | None = None  # the state the next observed graph should have

    def solve(self, graph: SceneGraph, instruction: str, goal: Goal | None = None) -> ReasonResult:
        """One episode from ``graph`` (see the module docstring); never raises for bad model output."""
        return SolveLoop(self.backend, self.domain, graph, instruction, self.options).run(goal)

    def reset(self, graph: SceneGraph, instruction: str, goal: Goal | None = None) -> ReasonResult:
        """Start a closed-loop episode: solve once from ``graph``; its checked steps become the plan."""
        self.instruction, self.replans, self.rejections = instruction, 0, 0
        result = self._adopt(graph, self.solve(graph, instruction, goal))
        self.goal = result.goal
        return result

    def step(self, graph: SceneGraph, feedback: Diagnosis | None = None) -> Step | None:
        """The next step for the observed ``graph``, or None when the reasoner has nothing left to do.

        Plans again (towards the goal found at reset) when ``feedback`` rejects the last step or the
        graph's state is not the one the plan expected.
        """
        if self.last is None:
            raise GSRError("Reasoner.step: call reset() first")
        rejected = feedback is not None and not feedback.ok
        if rejected or state_from_graph(graph, self.domain).atoms != self._expected:
            self.replans += 1
            self._adopt(graph, self.solve(graph, self.instruction, self.goal))
        if not self._plan:
            return None
        step, self._expected = self._plan.popleft()
        return step

    def _adopt(self, graph: SceneGraph, result: ReasonResult) -> ReasonResult:
        self.last = result
        self.rejections += result.rejections
        self._plan = deque((s.step, s.diagnosis.next_state.atoms) for s in result.steps)
        self._expected = state_from_graph(graph, self.domain).atoms
        return result


def solve(
    graph: SceneGraph,
    instruction: str,
    backend: Backend | Callable[[str], str] | str = "grounder",
    mode: str = "steps",
    domain: Domain | None = None,
    goal: Goal | None = None,
    examples: Sequence[Example] | None = None,
    max_steps: int = 40,
    max_repairs: int = 3,
    constrained: bool = False,
    require_effects: bool = False,
    show_goal: bool = True,
    prompt_actions: str = "pddl",
    planner: str = "lazy-ff",
    planner_timeout: float = 30.0,
    options: SolveOptions | None = None,
) -> ReasonResult:
    """Reach ``instruction`` from ``graph`` with checked steps; see the module docstring for the modes.

    The settings come from ``options`` when given (the keyword arguments are then ignored), else from
    the keyword arguments. Never raises for bad model output (it is diagnosed, repaired or reported in
    the result); raises GSRError only for bad arguments (unknown mode or backend spec).
    """
    if options is None:
        options = SolveOptions(
            mode=mode,
            max_steps=max_steps,
            max_repairs=max_repairs,
            constrained=constrained,
            require_effects=require_effects,
            show_goal=show_goal,
            prompt_actions=prompt_actions,
            planner=planner,
            planner_timeout=planner_timeout,
            examples=examples,
        )
    return Reasoner(backend, domain, options).solve(graph, instruction, goal)
