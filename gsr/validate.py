"""Plan validation: run the steps from the initial state, stop at the first invalid one, check the goal."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from gsr.check import check_step, repair_hints
from gsr.diagnosis import Diagnosis, Explainer, Reason, ReasonKind
from gsr.pddl.axioms import derive
from gsr.pddl.model import TRUE, Atom, Domain, Formula, Problem
from gsr.semantics import compile_domain
from gsr.state import State, initial_state
from gsr.step import Goal, Plan, Step


@dataclass(frozen=True)
class Report:
    """The verdict on a plan: per-step diagnoses, the first failing step, unsatisfied goal literals."""

    valid: bool
    steps: tuple[Diagnosis, ...]
    final_state: State
    failed_step: int | None = None
    goal_reached: bool = False
    goal_reasons: tuple[Reason, ...] = ()
    goal_hints: tuple[str, ...] = ()
    cost: float = 0.0
    plan_length: int = 0
    extras: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    @property
    def failure(self) -> Diagnosis | None:
        """The diagnosis of the first invalid step, if any."""
        return None if self.failed_step is None else self.steps[self.failed_step]

    @property
    def message(self) -> str:
        """One line: valid with cost, or the first problem."""
        if self.valid:
            return f"plan valid: {self.plan_length} step(s), cost {self.cost:g}, goal reached"
        if self.failure is not None:
            return f"plan invalid: step {self.failed_step + 1} {self.failure.message}"
        first = self.goal_reasons[0].detail if self.goal_reasons else "goal is false"
        more = f" (+{len(self.goal_reasons) - 1} more)" if len(self.goal_reasons) > 1 else ""
        return f"plan invalid: all {self.plan_length} step(s) apply but {first}{more}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form."""
        return {
            "valid": self.valid,
            "message": self.message,
            "plan_length": self.plan_length,
            "steps_checked": len(self.steps),
            "failed_step": self.failed_step,
            "failure": None if self.failure is None else self.failure.to_dict(),
            "goal_reached": self.goal_reached,
            "goal_reasons": [r.to_dict() for r in self.goal_reasons],
            "goal_hints": list(self.goal_hints),
            "cost": self.cost,
        }

    def __str__(self) -> str:
        lines = [self.message]
        for i, d in enumerate(self.steps, start=1):
            mark = "ok " if d.ok else "ERR"
            lines.append(f"  {i:>3} {mark} {d.step}")
            if not d.ok:
                lines.extend(f"          - {r.detail}" for r in d.reasons)
                lines.extend(f"          hint: {h}" for h in d.hints)
        if self.failed_step is not None and self.plan_length > len(self.steps):
            lines.append(f"  ({self.plan_length - len(self.steps)} later step(s) not checked)")
        if self.goal_reasons:
            lines.append("  goal not reached:")
            lines.extend(f"          - {r.detail}" for r in self.goal_reasons)
            lines.extend(f"          hint: {h}" for h in self.goal_hints)
        elif self.goal_reached:
            lines.append("  goal reached")
        return "\n".join(lines)


def explain_goal(domain: Domain, goal: Formula | Goal, state: State) -> tuple[list[Reason], list[str]]:
    """GOAL_UNSATISFIED reasons (one per false goal literal) and repair hints; empty when it holds."""
    formula = goal.formula if isinstance(goal, Goal) else goal
    cd = compile_domain(domain)
    explainer = Explainer(cd, state)
    if explainer.holds(formula, {}):
        return [], []
    failures = explainer.explain(formula, {})
    reasons = [
        Reason(ReasonKind.GOAL_UNSATISFIED, f.sentence("goal"), f.literal, f.bindings) for f in failures
    ]
    return reasons, repair_hints(cd, state, failures)


def validate_plan(
    domain: Domain,
    problem_or_state: Problem | State,
    plan: Plan | Iterable[Step],
    goal: Formula | Goal | None = None,
    numeric: Mapping[Atom, float] | None = None,
) -> Report:
    """Run ``plan`` from the problem's initial state (or a State), then check the goal (the problem's by default).

    Only the states the plan visits are evaluated (nothing is grounded); with derived predicates
    each visited state gets their stratified fixpoint (gsr.pddl.axioms.derive) before its step
    and the goal are checked.
    """
    if isinstance(problem_or_state, Problem):
        state = initial_state(domain, problem_or_state)
        if goal is None:
            goal = problem_or_state.goal
        if numeric is None:
            numeric = problem_or_state.init_numeric
    else:
        state = problem_or_state
    if goal is None:
        goal = TRUE
    closed = bool(domain.axioms)
    if closed:
        state = state.with_atoms(derive(domain, state.objects, state.atoms))
    steps = tuple(plan.steps if isinstance(plan, Plan) else plan)
    diagnoses: list[Diagnosis] = []
    cost = 0.0
    failed = None
    for i, step in enumerate(steps):
        diagnosis = check_step(domain, state, step, numeric)
        diagnoses.append(diagnosis)
        if not diagnosis.ok:
            failed = i
            break
        cost += diagnosis.cost
        state = diagnosis.next_state
        if closed:
            state = state.with_atoms(derive(domain, state.objects, state.atoms))
    goal_reasons, goal_hints = explain_goal(domain, goal, state)
    return Report(
        valid=failed is None and not goal_reasons,
        steps=tuple(diagnoses),
        final_state=state,
        failed_step=failed,
        goal_reached=not goal_reasons,
        goal_reasons=tuple(goal_reasons),
        goal_hints=tuple(goal_hints),
        cost=cost,
        plan_length=len(steps),
    )
