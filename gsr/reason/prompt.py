"""Prompts for the LLM reasoner: the compact scene, the domain's actions, the instruction, examples.

Layout of a steps-mode prompt (``Prompt.text()`` joins the two parts for completion models,
``Prompt.messages()`` gives them as chat messages)::

    [system] role, the domain's actions (PDDL signatures, preconditions, effects), the step syntax,
             few-shot examples (scene, instruction, the full checked solution)
    [user]   Scene: objects / relations (gsr.graph_text) and the facts the text does not show
             Instruction: ...   (Goal: ... when it is known)
             Steps so far: ...  Rejected for this step: <step> -> <diagnosis>
             Next step:

A goal-mode prompt asks for one PDDL goal formula over the scene's names instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from gsr.diagnosis import typed_text
from gsr.pddl.model import Domain, Formula
from gsr.pddl.writer import effect_inline, inline_formula
from gsr.reason.examples import Example, default_examples
from gsr.reason.scene_text import scene_text
from gsr.reason.step_format import format_step
from gsr.scene_graph import SceneGraph
from gsr.step import Goal, Step

DONE = "(done)"

STEP_RULES = """Step format: one step per line: the ground action in parentheses, then every change it makes in the current state: +(atom) for each atom it makes true, -(atom) for each atom it makes false. Use the exact object names of the scene; a part is named object/part (e.g. short_cabinet/drawer_low). Answer with exactly one step line and nothing else. If the instruction is already achieved, answer (done)."""

GOAL_RULES = """Answer with one PDDL goal formula over the scene's object names and the predicates above, on one line and nothing else: e.g. (and (in red_cube1 blue_box) (not (open short_cabinet/drawer_low))). Quantifiers are allowed: (forall (?x - cube) (imply (has_color ?x red) (in ?x blue_box)))."""


@dataclass(frozen=True)
class Prompt:
    """A prompt as a system part and a user part."""

    system: str
    user: str
    cue: str = field(default="Next step:")

    def messages(self) -> list[dict[str, str]]:
        """Chat messages (system, user) for chat models."""
        return [{"role": "system", "content": self.system}, {"role": "user", "content": self.user}]

    def text(self) -> str:
        """One plain text for completion models (ends with the answer cue and a newline)."""
        return f"{self.system}\n\n{self.user}\n"


def action_text(domain: Domain, detail: str = "pddl") -> str:
    """The domain's actions: ``(pick ?o - thing ?from - thing)`` with precondition and effect (``pddl``)."""
    lines = []
    for action in domain.actions.values():
        head = f"({' '.join(filter(None, (action.name, typed_text(action.params))))})"
        if detail == "signatures":
            lines.append(head)
        else:
            lines.append(
                f"{head}\n  pre: {inline_formula(action.precondition)}\n  eff: {effect_inline(action.effect)}"
            )
    return "\n".join(lines)


def predicate_text(domain: Domain) -> str:
    """The domain's predicates with typed parameters, one per line."""
    return "\n".join(
        f"({' '.join(filter(None, (p.name, typed_text(p.params))))})" for p in domain.predicates.values()
    )


def _goal_line(goal: Goal | Formula | None) -> str:
    if goal is None:
        return ""
    formula = goal.formula if isinstance(goal, Goal) else goal
    return f"Goal: {inline_formula(formula)}\n"


def build_prompt(
    graph: SceneGraph,
    domain: Domain,
    instruction: str,
    examples: Sequence[Example] | None = None,
    history: Sequence[Step] = (),
    rejected: Sequence[tuple[str, str]] = (),
    goal: Goal | Formula | None = None,
    actions: str = "pddl",
) -> Prompt:
    """The steps-mode prompt for the next step from ``graph`` (the current scene).

    ``examples`` defaults to the built-in example (pass ``()`` for none); ``history`` holds the
    steps already executed; ``rejected`` the (reply, diagnosis) pairs already tried for this step.
    """
    if examples is None:
        examples = default_examples(domain)
    parts = [
        "You control a one-armed robot. You read a scene graph and emit state-transition steps; "
        "a PDDL checker validates every step before it is executed.",
        f"Actions:\n{action_text(domain, actions)}",
        STEP_RULES,
    ]
    parts.extend(f"Example {i}:\n{ex.text()}" for i, ex in enumerate(examples, 1))
    user = [
        f"Scene:\n{scene_text(graph, domain)}",
        f"Instruction: {instruction}\n{_goal_line(goal)}".rstrip(),
    ]
    if history:
        user.append("Steps so far:\n" + "\n".join(format_step(s) for s in history))
    if rejected:
        tries = "\n".join(f"{reply.strip() or '(empty)'}\n  rejected: {why}" for reply, why in rejected)
        user.append(f"Rejected for this step (fix the problem):\n{tries}")
    user.append("Next step:")
    return Prompt("\n\n".join(parts), "\n".join(user), "Next step:")


def build_goal_prompt(
    graph: SceneGraph,
    domain: Domain,
    instruction: str,
    examples: Sequence[Example] | None = None,
    rejected: Sequence[tuple[str, str]] = (),
) -> Prompt:
    """The goal-mode prompt: the model answers one PDDL goal formula for ``instruction``."""
    if examples is None:
        examples = default_examples(domain)
    parts = [
        "You translate robot instructions into PDDL goals over a scene graph; a planner then sequences them.",
        f"Predicates:\n{predicate_text(domain)}",
        GOAL_RULES,
    ]
    parts.extend(f"Example {i}:\n{ex.text(goal_mode=True)}" for i, ex in enumerate(examples, 1) if ex.goal)
    user = [f"Scene:\n{scene_text(graph, domain)}", f"Instruction: {instruction}"]
    if rejected:
        tries = "\n".join(f"{reply.strip() or '(empty)'}\n  rejected: {why}" for reply, why in rejected)
        user.append(f"Rejected goals (fix the problem):\n{tries}")
    user.append("Goal:")
    return Prompt("\n\n".join(parts), "\n".join(user), "Goal:")
