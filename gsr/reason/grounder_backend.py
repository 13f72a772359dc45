"""The embedded default backend: goals from gsr.language.ground, steps from the planner (no model)."""

from __future__ import annotations

from collections.abc import Sequence

from gsr.diagnosis import formula_text
from gsr.language import ground
from gsr.pddl.model import Domain
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.reason.backend import BackendError, GoalUnreachable, Query
from gsr.reason.examples import annotate_steps
from gsr.reason.prompt import DONE, Prompt
from gsr.reason.step_format import format_step
from gsr.scene_graph import SceneGraph
from gsr.step import Goal, Step


def ground_goal(query: Query) -> Goal:
    """The embedded grounder's goal for the query's instruction (its GSRError when it finds none)."""
    return ground(query.instruction, query.graph, domain=query.domain)


class GrounderBackend:
    """A deterministic reasoner: answers goal queries with the grounder and step queries with the planner."""

    name = "grounder"

    def __init__(self, planner: str = "lazy-ff", timeout: float = 30.0) -> None:
        self.planner = planner
        self.timeout = timeout

    def complete(self, prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str:
        """The goal formula, or the next planned step with its effects (``(done)`` when the goal holds)."""
        if query is None:
            raise BackendError("the grounder backend needs the structured query, not only the prompt text")
        goal = query.goal if query.goal is not None else ground_goal(query)
        if query.kind == "goal":
            return formula_text(goal.formula)
        steps = self.propose_plan(query.domain, query.graph, goal)
        if not steps:
            return DONE
        first = annotate_steps(query.domain, query.graph, steps[:1])[0]
        return format_step(first)

    def propose_plan(self, domain: Domain, graph: SceneGraph, goal: Goal) -> list[Step]:
        """The planner's whole plan from ``graph`` to ``goal`` (the loop's :class:`PlanProposer` path)."""
        result = plan_api.plan_graph(domain, graph, goal, planner=self.planner, timeout=self.timeout)
        if result.status == "unsolvable":
            raise GoalUnreachable(f"the planner proves the goal unreachable: {result.message}")
        if not result.solved or result.plan is None:
            raise BackendError(f"the planner found no plan ({result.status}): {result.message}")
        return list(result.plan.steps)
