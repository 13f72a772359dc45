"""The reasoner's step language: one state-transition step per line, parsed with a lark grammar.

A step line is the ground action followed by the effects the model claims::

    (place_in bowl_1 cabinet_1/bottom_drawer) +(in bowl_1 cabinet_1/bottom_drawer) -(holding bowl_1) +(hand_empty)

``+atom`` is a claimed add effect, ``-atom`` a claimed delete effect. A line with at least one
effect claims the *complete* change (the checker reports both missing and spurious effects); a line
with no effects makes no claim (only the action is checked). A leading list marker (``-``, ``*``,
``3.``, ``3)``, ``step 3:``) is ignored, as are blank lines, ``;`` / ``#`` comments and Markdown code
fences. The same step as JSON, one object per line or a JSON list of objects::

    {"action": "place_in", "args": ["bowl_1", "cabinet_1/bottom_drawer"],
     "add": ["(in bowl_1 cabinet_1/bottom_drawer)", "(hand_empty)"], "delete": ["(holding bowl_1)"]}

Atoms in JSON may also be lists (``["in", "bowl_1", "cabinet_1/bottom_drawer"]``). Names are
lower-cased (PDDL is case-insensitive). Every syntax error is a :class:`gsr.errors.ParseError`
with line and column. A line is read by the one step grammar (:mod:`gsr.step_grammar`) with effects
on; IPC plan files use the same grammar with effects off.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable
from typing import Any

from gsr.errors import ParseError
from gsr.pddl.model import Atom
from gsr.step import Step
from gsr.step_grammar import STEP_GRAMMAR, parse_step_text

__all__ = [
    "STEP_GRAMMAR",
    "content_lines",
    "format_step",
    "format_steps",
    "parse_first_step",
    "parse_step_line",
    "parse_steps",
    "step_from_json",
]

_NAME_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_\-./@#]*")
_FENCE = re.compile(r"^\s*```")
_COMMENT = re.compile(r"\s(;|#).*$|^\s*(;|#).*$")


def parse_step_line(line: str, source: str = "<step>", lineno: int = 1) -> Step:
    """Parse one step line (text syntax) into a Step; raises ParseError with line and column."""
    return parse_step_text(line, source, lineno, effects=True)


def _json_atom(value: Any, where: str, source: str, lineno: int) -> Atom:
    """An atom from ``"(in a b)"`` or ``["in", "a", "b"]``."""
    if isinstance(value, str):
        step = parse_step_line(value, source, lineno) if value.strip().startswith("(") else None
        if step is not None and step.add is None:
            return Atom(step.action, step.args)
    elif (
        isinstance(value, list)
        and value
        and all(isinstance(v, str) and _NAME_RE.fullmatch(v.strip()) for v in value)
    ):
        return Atom(value[0].strip().lower(), tuple(v.strip().lower() for v in value[1:]))
    raise ParseError(
        f'{where}: expected an atom such as "(in a b)", got {value!r}', source=source, line=lineno, column=1
    )


def step_from_json(data: Any, source: str = "<step>", lineno: int = 1) -> Step:
    """A Step from a parsed JSON object ``{"action", "args", "add"?, "delete"?}``."""
    if not isinstance(data, dict):
        raise ParseError(
            f"expected a JSON object, got {type(data).__name__}", source=source, line=lineno, column=1
        )
    unknown = sorted(set(data) - {"action", "args", "add", "delete"})
    if unknown:
        raise ParseError(f"unknown field(s) {', '.join(unknown)}", source=source, line=lineno, column=1)
    action = data.get("action")
    if not isinstance(action, str) or not _NAME_RE.fullmatch(action.strip()):
        raise ParseError(
            f"field 'action': expected an action name, got {action!r}", source=source, line=lineno, column=1
        )
    args = data.get("args", [])
    if not isinstance(args, list) or not all(
        isinstance(a, str) and _NAME_RE.fullmatch(a.strip()) for a in args
    ):
        raise ParseError(
            f"field 'args': expected a list of names, got {args!r}", source=source, line=lineno, column=1
        )
    claims: dict[str, tuple[Atom, ...] | None] = {}
    for key in ("add", "delete"):
        value = data.get(key)
        if value is not None and not isinstance(value, list):
            raise ParseError(f"field {key!r}: expected a list of atoms", source=source, line=lineno, column=1)
        claims[key] = (
            None if value is None else tuple(_json_atom(v, f"field {key!r}", source, lineno) for v in value)
        )
    add, delete = claims["add"], claims["delete"]
    if add is not None or delete is not None:  # one list given claims the other is empty
        add, delete = add or (), delete or ()
    return Step(action.strip().lower(), tuple(a.strip().lower() for a in args), add, delete)


def content_lines(text: str) -> Iterable[tuple[int, str]]:
    """(line number, text) of the lines that can hold steps: no blanks, comments or code fences."""
    for lineno, raw in enumerate(text.splitlines(), start=1):
        if _FENCE.match(raw):
            continue
        line = _COMMENT.sub("", raw).rstrip()
        if line.strip():
            yield lineno, line


def parse_steps(text: str, source: str = "<steps>") -> list[Step]:
    """Parse reasoner output: step lines or JSON (objects per line, or one list); ParseError on bad input."""
    content = dict(content_lines(text))
    # blank out fences and comments but keep the line count, so JSON error positions stay true
    kept = "\n".join(content.get(i, "") for i in range(1, text.count("\n") + 2))
    stripped = kept.strip()
    if stripped.startswith("["):
        try:
            data = json.loads(kept)
        except json.JSONDecodeError as exc:
            raise ParseError(
                f"invalid JSON: {exc.msg}", source=source, line=exc.lineno, column=exc.colno
            ) from None
        if not isinstance(data, list):
            raise ParseError("expected a JSON list of steps", source=source, line=1, column=1)
        return [step_from_json(item, source, 1) for item in data]
    steps = []
    for lineno, line in content_lines(text):
        if line.lstrip().startswith("{"):
            try:
                data = json.loads(line)
            except json.JSONDecodeError as exc:
                raise ParseError(
                    f"invalid JSON: {exc.msg}", source=source, line=lineno, column=exc.colno
                ) from None
            steps.append(step_from_json(data, source, lineno))
        else:
            steps.append(parse_step_line(line, source, lineno))
    return steps


def parse_first_step(text: str, source: str = "<reply>") -> Step:
    """The first step of a model reply (later lines are ignored); ParseError when there is none."""
    for lineno, line in content_lines(text):
        if line.lstrip().startswith("{"):
            return parse_steps(line, source)[0]
        return parse_step_line(line, source, lineno)
    raise ParseError("no step in the reply (it is empty)", source=source, line=1, column=1)


def _atom_text(atom: Atom) -> str:
    return f"({' '.join((atom.predicate, *atom.args))})"


def format_step(step: Step, json_format: bool = False) -> str:
    """One step as a line of the step language (or as a JSON object with ``json_format``)."""
    if json_format:
        data: dict[str, Any] = {"action": step.action, "args": list(step.args)}
        if step.claims_effects:
            data["add"] = [_atom_text(a) for a in step.add or ()]
            data["delete"] = [_atom_text(a) for a in step.delete or ()]
        return json.dumps(data)
    parts = [str(Step(step.action, step.args))]
    parts.extend(f"+{_atom_text(a)}" for a in step.add or ())
    parts.extend(f"-{_atom_text(a)}" for a in step.delete or ())
    return " ".join(parts)


def format_steps(steps: Iterable[Step], json_format: bool = False) -> str:
    """Steps one per line (text or JSON lines), newline-terminated."""
    return "".join(format_step(s, json_format) + "\n" for s in steps)
