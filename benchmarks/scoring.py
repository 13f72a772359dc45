"""Episode scoring: strict success and GenManip-style partial credit over goal alternatives.

A task's goal and its ``goal_alternatives`` are each a formula; for a conjunction its conjuncts are the
*relations* to satisfy. The strict verdict is "some alternative holds"; the partial score is the best
alternative's fraction of satisfied relations (1.0 exactly when strict success). Goal-condition recall
is the same fraction for the canonical goal alone.
"""

from __future__ import annotations

from dataclasses import dataclass

from gsr.pddl.model import Domain, Formula, Or
from gsr.semantics import conjuncts, holds
from gsr.state import State
from gsr.task_spec import TaskSpec


@dataclass(frozen=True)
class Score:
    """Strict success, the best alternative's satisfied fraction and which alternative that was."""

    success: bool
    score: float
    best: int
    satisfied: int
    total: int
    recall: float


def relations(formula: Formula) -> tuple[Formula, ...]:
    """The relations a goal asks for: the conjuncts of a conjunction, else the formula itself."""
    parts = conjuncts(formula)
    return parts or (formula,)


def score_state(domain: Domain, formulas: tuple[Formula, ...], state: State) -> Score:
    """Score a final state against goal alternatives (the first is the canonical goal)."""
    best, best_frac, best_sat, best_total = 0, -1.0, 0, 0
    success = False
    recall = 0.0
    for i, f in enumerate(formulas):
        parts = relations(f)
        sat = sum(1 for p in parts if holds(domain, p, state))
        frac = sat / len(parts) if parts else 1.0
        if i == 0:
            recall = frac
        if sat == len(parts) and holds(domain, f, state):
            success = True
            frac = 1.0
        if frac > best_frac:
            best, best_frac, best_sat, best_total = i, frac, sat, len(parts)
    return Score(success, round(best_frac, 6), best, best_sat, best_total, round(recall, 6))


def score_task(domain: Domain, task: TaskSpec, state: State) -> Score:
    """Score a final state against a task's goal and alternatives."""
    return score_state(domain, task.goal_formulas(), state)


def any_goal(task: TaskSpec) -> Formula:
    """The goal a planner should reach: the canonical goal, or the disjunction of all alternatives."""
    formulas = task.goal_formulas()
    return formulas[0] if len(formulas) == 1 else Or(tuple(formulas))
