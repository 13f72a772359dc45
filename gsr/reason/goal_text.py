"""A model's goal answer: PDDL formula text, parsed and checked against the domain and the scene."""

from __future__ import annotations

import difflib

from gsr.errors import GSRError, ParseError
from gsr.pddl.model import Atom, Domain, Formula, is_variable
from gsr.pddl.parser import parse_formula
from gsr.pddl.walk import bound_variables, free_variables, subformulas, terms
from gsr.reason.step_format import content_lines
from gsr.state import State
from gsr.step import Goal


class GoalRejected(GSRError):
    """A goal answer that does not parse or names unknown predicates, objects or types."""


def _near(word: str, choices: list[str]) -> str:
    close = difflib.get_close_matches(word, choices, n=3, cutoff=0.6)
    return f" (did you mean {', '.join(close)}?)" if close else ""


def goal_problems(domain: Domain, state: State, formula: Formula) -> list[str]:
    """What is wrong with a goal formula: unknown predicates, wrong arity, unknown objects or types, free variables."""
    problems: list[str] = []
    objects = sorted(state.objects)
    for node in subformulas(formula):
        for t in (t for var in bound_variables(node) for t in var.types):
            if t not in domain.types:
                problems.append(f"unknown type {t}{_near(t, sorted(domain.types))}")
        if isinstance(node, Atom):
            pred = domain.predicates.get(node.predicate)
            if pred is None:
                problems.append(
                    f"unknown predicate {node.predicate}{_near(node.predicate, sorted(domain.predicates))}"
                )
                continue
            if pred.arity != len(node.args):
                problems.append(
                    f"{node} has {len(node.args)} argument(s); {node.predicate} takes {pred.arity}"
                )
        for term in terms(node):
            if not is_variable(term) and term not in state.objects:
                problems.append(f"unknown object {term}{_near(term, objects)}")
    free = sorted(free_variables(formula))
    if free:
        problems.append(f"unbound variable(s) {', '.join(free)}: quantify them with forall/exists")
    return list(dict.fromkeys(problems))


def parse_goal_answer(text: str, domain: Domain, state: State, instruction: str | None = None) -> Goal:
    """The first formula in a model's goal answer as a Goal; GoalRejected with the reasons otherwise."""
    lines = [line.strip() for _, line in content_lines(text)]
    body = " ".join(lines)
    if body.lower().startswith("goal:"):
        body = body[5:].strip()
    if not body:
        raise GoalRejected("the answer is empty: expected one PDDL goal formula")
    try:
        formula = parse_formula(body, source="goal")
    except ParseError as exc:
        raise GoalRejected(f"the goal does not parse: {exc}") from None
    problems = goal_problems(domain, state, formula)
    if problems:
        raise GoalRejected("; ".join(problems))
    return Goal(formula, instruction)
