"""Task synthesis: plan sampled goals on a scene with our planner and keep only validated plans.

Grounding dominates planning time on these scenes (~100x the search), so a :class:`SceneEngine`
grounds a scene once from its initial state and plans a chain of tasks on it: each task starts
where the previous one ended. That is sound because the grounder keeps every operator that is
relaxed-reachable from the initial state, a superset of those applicable in any reachable state.
Every plan is then run through :func:`gsr.validate.validate_plan` (the checker, not the planner's
own model); the per-step states it returns are the supervision targets.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass

from gsr.datagen.goals import GoalLiteral, goal_formula
from gsr.datagen.scene import Scene
from gsr.datagen.serialize import graph_dict
from gsr.facts import DYNAMIC_PREDICATES, problem_from_graph, state_from_graph
from gsr.pddl.model import TRUE, Atom, Domain
from gsr.plan.grounding import ground_goal, ground_task, normalize_action
from gsr.plan.heuristics import Relaxation
from gsr.plan.search import lazy_gbfs
from gsr.plan.task import Task, mask
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.validate import validate_plan


@dataclass(frozen=True, slots=True)
class PlannedTask:
    """A validated task: goal, plan, the state before each step and the final state (dynamic atoms)."""

    goal: tuple[GoalLiteral, ...]
    steps: tuple[Step, ...]  # with the complete true add/delete effects, from the checker
    states: tuple[frozenset[Atom], ...]  # len(steps) + 1 dynamic states, states[0] is the start


_FLUENTS: dict[int, tuple[Domain, frozenset[str]]] = {}


def _fluents(domain: Domain) -> frozenset[str]:
    """Predicates some action changes (cached per domain object; the grounder computes the same set)."""
    hit = _FLUENTS.get(id(domain))
    if hit is None or hit[0] is not domain:
        preds = frozenset(
            e.literal.atom.predicate for a in domain.actions.values() for e in normalize_action(a).effects
        )
        hit = _FLUENTS[id(domain)] = (domain, preds)
    return hit[1]


def scene_graph(scene: Scene, atoms: frozenset[Atom]) -> SceneGraph:
    """The validated SceneGraph of a scene in a state (used once per scene; samples use plain dicts)."""
    return SceneGraph.model_validate(graph_dict(scene, atoms))


def dynamic(atoms: frozenset[Atom]) -> frozenset[Atom]:
    """Only the dynamic atoms (support, doors, power, hand): what a scene graph shows."""
    return frozenset(a for a in atoms if a.predicate in DYNAMIC_PREDICATES)


class GroundedScene:
    """A scene structure grounded once (the expensive part); shared by every reskin of it."""

    def __init__(self, domain: Domain, scene: Scene, initial: frozenset[Atom]) -> None:
        graph = scene_graph(scene, initial)
        self.domain = domain
        self.scene = scene
        self.problem = problem_from_graph(graph, TRUE, domain=domain)
        self.task = ground_task(domain, self.problem)
        self.ids = {a: i for i, a in enumerate(self.task.atoms)}
        self.fluent = set(_fluents(domain))

    def covers(self, atoms: frozenset[Atom]) -> bool:
        """True when every fluent atom is relaxed-reachable here, so the grounding is valid from ``atoms``."""
        return all(a in self.ids for a in atoms if a.predicate in self.fluent)


class SceneEngine:
    """One concrete scene (same structure as its GroundedScene): plans a chain of goals from a state."""

    def __init__(self, grounded: GroundedScene, scene: Scene, initial: frozenset[Atom]) -> None:
        self.grounded = grounded
        self.domain = grounded.domain
        self.scene = scene
        self.to_base = {o.id: b.id for o, b in zip(scene.objects, grounded.scene.objects, strict=True)}
        self.from_base = {b: o for o, b in self.to_base.items()}
        self.state = state_from_graph(scene_graph(scene, initial), self.domain)
        self.rejected = 0  # plans the checker refused (expected 0; counted and reported by the runner)

    def _base_atom(self, a: Atom) -> Atom:
        m = self.to_base
        return Atom(a.predicate, tuple(m.get(x, x) for x in a.args))

    def valid_start(self) -> bool:
        """True when the grounding covers this scene's current state (else the caller regrounds)."""
        return self.grounded.covers(frozenset(self._base_atom(a) for a in self.state.atoms))

    def plan(self, goal: list[GoalLiteral], timeout: float = 2.0) -> PlannedTask | None:
        """Plan ``goal`` from the current state and validate it; None when unsolved or rejected."""
        g = self.grounded
        formula = goal_formula(goal)
        base_goal = goal_formula(
            [GoalLiteral(x.predicate, tuple(self.to_base[a] for a in x.args), x.positive) for x in goal]
        )
        goals = ground_goal(self.domain, g.problem, base_goal, g.ids, g.fluent)
        if not goals:
            return None
        init = 0
        for a in self.state.atoms:
            if a.predicate in g.fluent:
                i = g.ids.get(self._base_atom(a))
                if i is None:
                    return None  # outside the grounding: cannot happen from a covered start
                init |= 1 << i
        task = _retarget(g.task, init, goals)
        if task.is_goal(init):
            return None
        result = lazy_gbfs(task, Relaxation(task), time.perf_counter() + timeout)
        if result.status != "solved":
            return None
        fb = self.from_base
        plan = [Step(task.ops[i].name, tuple(fb.get(x, x) for x in task.ops[i].args)) for i in result.ops]
        # the plan is checked against the concrete scene's own state by the checker, independently
        report = validate_plan(self.domain, self.state, plan, formula)
        if not report.valid:
            self.rejected += 1
            return None
        states = [dynamic(self.state.atoms)]
        steps: list[Step] = []
        before = self.state.atoms
        for step, diagnosis in zip(plan, report.steps, strict=True):
            after = diagnosis.next_state.atoms
            # the complete true change (cube counters included): what a reasoner's step line must claim
            add = tuple(sorted(after - before, key=str))
            delete = tuple(sorted(before - after, key=str))
            steps.append(Step(step.action, step.args, add=add, delete=delete))
            states.append(dynamic(after))
            before = after
        self.state = report.final_state
        return PlannedTask(tuple(goal), tuple(steps), tuple(states))

    def current(self) -> frozenset[Atom]:
        """The dynamic atoms of the current state."""
        return dynamic(self.state.atoms)


def _retarget(base: Task, init: int, goals: list) -> Task:
    """The grounded task with another initial state and goal (operators and masks shared)."""
    task = copy.copy(base)
    task.init = init
    task.goals = goals
    task.goal_masks = [(mask(p), mask(n)) for p, n in goals]
    task.has_neg = any(o.neg for o in task.ops) or any(n for _, n in goals)
    return task


def graph_from_state(scene: Scene, state: State | frozenset[Atom]) -> SceneGraph:
    """Convenience for tests and tools: the SceneGraph of a scene in a state."""
    atoms = state.atoms if isinstance(state, State) else state
    return scene_graph(scene, dynamic(atoms))
