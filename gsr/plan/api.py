"""Public planning API: ``plan(domain, problem)`` and ``plan_graph(domain, graph, goal)``."""

from __future__ import annotations

import gc
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from gsr.errors import GSRError
from gsr.pddl.model import Domain, Formula, Problem
from gsr.pddl.writer import write_domain, write_problem
from gsr.plan.grounding import GroundingTimeout, ground_task
from gsr.plan.heuristics import INF, Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.search import (
    GOALS_ONLY_LAMA,
    LAMA_FIRST,
    SearchResult,
    breadth_first,
    eager_search,
    lazy_gbfs,
    lazy_lama,
)
from gsr.plan.task import Task
from gsr.step import Goal, Plan

if TYPE_CHECKING:  # the scene graph (and pydantic) only for plan_graph's callers, not for PDDL files:
    # plan_graph imports gsr.facts when called (0.2 s CPU of imports a PDDL run does not need)
    from gsr.scene_graph import SceneGraph

PLANNERS = ("lazy-ff", "lama", "gbfs-ff", "astar-lmcut", "astar-hmax", "astar-blind", "bfs", "fd")
OPTIMAL = frozenset({"astar-lmcut", "astar-hmax", "astar-blind"})


@dataclass(frozen=True, slots=True)
class PlanResult:
    """Outcome of a planner call; ``time`` is ``ground_time + search_time`` in seconds."""

    status: str  # "solved" | "unsolvable" | "timeout" | "error"
    plan: Plan | None
    cost: float | None
    expanded: int
    generated: int
    evaluated: int
    time: float
    ground_time: float
    search_time: float
    planner: str
    message: str = ""
    operators: int | None = None  # ground operators and atoms (None when grounding did not finish)
    atoms: int | None = None

    @property
    def solved(self) -> bool:
        """True when a plan was found."""
        return self.status == "solved"


def lama(task: Task, relax: Relaxation, deadline: float) -> SearchResult:
    """Planner ``lama``: ``lazy_lama`` with ``LAMA_FIRST`` on GSR's landmark graph; where that graph
    is goals only (``Landmarks.goals_only``) and RHW's disjunctive landmarks add at least one, with
    ``GOALS_ONLY_LAMA`` on the disjunctive graph instead (issue 18, eighth pass: transport-sat08)."""
    landmarks = Landmarks(task, disjunctive=LAMA_FIRST.disjunctive)
    options = LAMA_FIRST
    if not LAMA_FIRST.disjunctive and landmarks.goals_only():
        mutexes = landmarks.orders.mutexes if landmarks.orders is not None else None
        richer = Landmarks(task, disjunctive=True, mutexes=mutexes)
        if len(richer.lm_facts) > len(landmarks.lm_facts):
            landmarks, options = richer, GOALS_ONLY_LAMA
    return lazy_lama(task, relax, landmarks, deadline, options)


def _search(task: Task, relax: Relaxation, planner: str, deadline: float) -> tuple[SearchResult, str]:
    if planner == "lazy-ff":
        return lazy_gbfs(task, relax, deadline), "lazy GBFS, h_FF, preferred operators"
    if planner == "lama":
        return lama(task, relax, deadline), "lazy GBFS, h_FF + landmark count, preferred operators"
    if planner == "gbfs-ff":
        return eager_search(task, lambda s: relax.ff(s)[0], deadline, 0.0), "eager GBFS, h_FF"
    if planner == "astar-lmcut":
        if task.has_cond:
            # LM-cut over per-effect unary operators is not admissible with conditional effects.
            return eager_search(
                task, relax.hmax_value, deadline, 1.0
            ), "A*, h_max (conditional effects: LM-cut n/a)"
        return eager_search(task, relax.lmcut, deadline, 1.0), "A*, LM-cut"
    if planner == "astar-hmax":
        return eager_search(task, relax.hmax_value, deadline, 1.0), "A*, h_max"
    if planner == "astar-blind":
        return eager_search(task, lambda s: 0.0, deadline, 1.0), "A*, blind"
    if planner == "bfs":
        if not task.unit_cost:
            return eager_search(task, lambda s: 0.0, deadline, 1.0), "uniform-cost search (non-unit costs)"
        return breadth_first(task, deadline), "breadth-first search"
    raise GSRError(f"unknown planner {planner!r}; choose one of {', '.join(PLANNERS)}")


def _plan_fd(domain: Domain, problem: Problem, timeout: float) -> PlanResult:
    # Deferred: a run of our own planner loads neither the FD driver (8 ms) nor the validator (24 ms,
    # tests/gsr/test_plan_bench_isolated.py: an isolated benchmark run pays only for planning's imports).
    from gsr.plan.fast_downward import run_fast_downward
    from gsr.validate import validate_plan

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="gsr-plan-") as tmp:
        dom, prob = Path(tmp) / "domain.pddl", Path(tmp) / "problem.pddl"
        dom.write_text(write_domain(domain))
        prob.write_text(write_problem(problem))
        status, found, message = run_fast_downward(dom, prob, timeout)
    elapsed = time.perf_counter() - start
    cost = None
    if found is not None:
        # FD's plan is checked like ours; its cost (action costs included) comes from the check.
        report = validate_plan(domain, problem, found)
        if not report.valid:
            return PlanResult(
                "error",
                None,
                None,
                0,
                0,
                0,
                elapsed,
                0.0,
                elapsed,
                "fd",
                f"Fast Downward's plan is invalid: {report.message}",
            )
        cost = report.cost
    return PlanResult(status, found, cost, 0, 0, 0, elapsed, 0.0, elapsed, "fd", message)


def plan(domain: Domain, problem: Problem, planner: str = "lazy-ff", timeout: float = 60.0) -> PlanResult:
    """Find a plan for ``problem``; ``status`` is "unsolvable" only when that is proven."""
    if planner == "fd":
        return _plan_fd(domain, problem, timeout)
    if planner not in PLANNERS:
        raise GSRError(f"unknown planner {planner!r}; choose one of {', '.join(PLANNERS)}")
    start = time.perf_counter()
    deadline = start + timeout
    # Grounding allocates many small acyclic objects; the cyclic collector only slows it (~5-10%).
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        task = ground_task(domain, problem, deadline)
    except GroundingTimeout:
        t = time.perf_counter() - start
        message = f"no plan within {timeout:g} s (grounding did not finish)"
        return PlanResult("timeout", None, None, 0, 0, 0, t, t, 0.0, planner, message)
    except GSRError as err:
        t = time.perf_counter() - start
        return PlanResult("error", None, None, 0, 0, 0, t, t, 0.0, planner, str(err))
    finally:
        if gc_was_enabled:
            gc.enable()
    ground_time = time.perf_counter() - start
    if not gc_was_enabled:
        return _plan_grounded(task, planner, start, ground_time, deadline, timeout)
    # The task lives until the plan is returned: frozen, the collections the search triggers do not
    # walk grounding's objects again (one first collection over them cost ~4% of a tabletop plan()).
    gc.freeze()
    try:
        return _plan_grounded(task, planner, start, ground_time, deadline, timeout)
    finally:
        gc.unfreeze()


def _plan_grounded(
    task: Task, planner: str, start: float, ground_time: float, deadline: float, timeout: float
) -> PlanResult:
    """Reachability check, search and the result of ``plan`` on a grounded task."""
    # Built once: the reachability check and the search share it. The greedy planners estimate
    # plan length (unit costs), as lama-first does; the optimal ones need the real costs.
    relax = Relaxation(task, unit=planner not in OPTIMAL and planner != "bfs")
    if not task.goals or relax.hadd(task.init)[0][relax.goal_fact] == INF:  # same reachability as h_max
        t = time.perf_counter() - start
        return PlanResult(
            "unsolvable",
            None,
            None,
            0,
            0,
            0,
            t,
            ground_time,
            t - ground_time,
            planner,
            "goal is unreachable even ignoring delete effects",
            len(task.ops),
            len(task.atoms),
        )
    result, how = _search(task, relax, planner, deadline)
    total = time.perf_counter() - start
    found = task.to_plan(result.ops) if result.status == "solved" else None
    cost = task.cost_of(result.ops) if found is not None else None
    message = f"{how}; {len(task.ops)} operators, {len(task.atoms)} atoms"
    if result.status == "timeout":
        message = f"no plan within {timeout:g} s ({how})"
    elif result.status == "unsolvable":
        message = f"search space exhausted: no plan exists ({how})"
    return PlanResult(
        result.status,
        found,
        cost,
        result.expanded,
        result.generated,
        result.evaluated,
        total,
        ground_time,
        total - ground_time,
        planner,
        message,
        len(task.ops),
        len(task.atoms),
    )


def plan_graph(
    domain: Domain | None,
    graph: SceneGraph,
    goal: Goal | Formula,
    planner: str = "lazy-ff",
    timeout: float = 60.0,
) -> PlanResult:
    """Plan from a scene graph to a goal (the problem is built by gsr.facts.problem_from_graph)."""
    from gsr.facts import default_domain, problem_from_graph

    domain = domain or default_domain()
    formula = goal.formula if isinstance(goal, Goal) else goal
    problem = problem_from_graph(graph, formula, domain=domain)
    return plan(domain, problem, planner=planner, timeout=timeout)
