"""Dataset rows -> (prompt, answer) pairs in the reasoner's own prompt and step language.

``next_action`` rows become exactly the prompt :func:`gsr.reason.prompt.build_prompt` sends at
inference (scene text, instruction, goal, steps so far with their effects, ``Next step:``) and the
answer is the step line :func:`gsr.reason.step_format.format_step` writes (or ``(done)``);
``goal_interpretation`` rows become :func:`build_goal_prompt` prompts answered by the PDDL goal.
``forward_prediction`` and ``inverse_action`` are auxiliary tasks in the same step language
(scene + action -> the step line with its effects; scenes -> plan lines); ``scene_abstraction``
answers the compact scene text. A model trained on these plugs into ``--backend transformers:DIR``.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from gsr.datagen.schema import decode
from gsr.graph_text import to_prompt_text
from gsr.pddl.model import Atom, Domain
from gsr.pddl.parser import parse_formula
from gsr.reason.prompt import DONE, Prompt, build_goal_prompt, build_prompt
from gsr.reason.scene_text import scene_text
from gsr.reason.step_format import format_step
from gsr.step import Step

DEFAULT_TYPES: tuple[str, ...] = ("next_action", "goal_interpretation", "forward_prediction")


@dataclass(frozen=True, slots=True)
class Example:
    """One supervised example: the prompt text the backend will send and the answer line(s)."""

    prompt: str
    answer: str
    type: str
    id: str


def _atom(text: str) -> Atom:
    names = text.strip()[1:-1].split()
    return Atom(names[0], tuple(names[1:]))


def _step(data: Any, effects: bool = True):

    if not effects or data.add is None:
        return Step(data.action, tuple(data.args))
    return Step(
        data.action, tuple(data.args), tuple(map(_atom, data.add)), tuple(map(_atom, data.delete or ()))
    )


def _plain(prompt: Any, chat: Any | None) -> str:
    """The text the transformers backend feeds the model: chat template when the tokenizer has one."""
    if chat is not None:
        return chat.apply_chat_template(prompt.messages(), tokenize=False, add_generation_prompt=True)
    return prompt.text()


def row_example(row: dict[str, Any], domain: Domain, chat: Any | None = None) -> Example | None:
    """The training example of one dataset row (None for a type without a text form)."""
    envelope, inp, out = decode(row)
    kind = envelope.type
    if kind == "next_action":
        history = [_step(s) for s in inp.history]
        prompt = build_prompt(
            inp.graph, domain, inp.instruction, history=history, goal=parse_formula(inp.goal)
        )
        answer = DONE if out.done else format_step(_step(out.step))
    elif kind == "goal_interpretation":
        prompt = build_goal_prompt(inp.graph, domain, inp.instruction)
        answer = out.goal
    elif kind == "forward_prediction":
        user = f"Scene:\n{scene_text(inp.graph, domain)}\nAction: {format_step(_step(inp.step, False))}\nStep with effects:"
        prompt = Prompt(
            "Predict every change the action makes to the scene, as one step line.",
            user,
            "Step with effects:",
        )
        answer = format_step(
            Step(
                inp.step.action,
                tuple(inp.step.args),
                tuple(map(_atom, out.add)),
                tuple(map(_atom, out.delete)),
            )
        )
    elif kind == "inverse_action":
        user = f"Scene:\n{scene_text(inp.start_graph, domain)}\nTarget scene:\n{to_prompt_text(inp.goal_graph)}\nPlan:"
        prompt = Prompt(
            "Give the actions that turn the scene into the target scene, one per line.", user, "Plan:"
        )
        answer = "\n".join(format_step(_step(s, False)) for s in out.plan)
    elif kind == "scene_abstraction":
        objects = "\n".join(
            f"{o.id}: {o.caption} at ({', '.join(f'{v:g}' for v in o.position)}) size ({', '.join(f'{v:g}' for v in o.size)})"
            for o in inp.objects
        )
        prompt = Prompt(
            "Build the scene graph of the observed objects.",
            f"Objects:\n{objects}\nScene graph:",
            "Scene graph:",
        )
        answer = to_prompt_text(out.graph)
    else:  # pragma: no cover - decode() only admits the five types
        return None
    return Example(_plain(prompt, chat), answer, kind, envelope.id)


def read_rows(
    files: Iterable[str], types: tuple[str, ...], limit: int | None = None
) -> Iterator[dict[str, Any]]:
    """Rows of the given types from JSONL files, in file order, at most ``limit``."""
    n = 0
    for path in files:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                if limit is not None and n >= limit:
                    return
                row = json.loads(line)
                if row.get("type") in types:
                    n += 1
                    yield row
