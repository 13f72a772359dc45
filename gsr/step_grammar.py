"""The one grammar of step lines: a ground action in parentheses, with or without claimed effects.

Two places read step lines, and both parse them here (one lark grammar, one error format):

- the reasoner's step language (:mod:`gsr.reason.step_format`, ``effects=True``)::

      3. (place_in bowl_1 cabinet_1/bottom_drawer) +(in bowl_1 cabinet_1/bottom_drawer) -(holding bowl_1)

  an optional list marker (``-``, ``*``, ``3.``, ``3)``, ``step 3:``), the action, then ``+atom`` /
  ``-atom`` claimed add and delete effects;
- IPC plan files (:mod:`gsr.plan_format`, ``effects=False``)::

      1.5: (stack b a) [1]

  an optional ``t:`` timestamp, the action, an optional ``[d]`` duration, no effects; names may hold
  ``?`` and start with ``-`` as planners write them.

Names are lower-cased (PDDL is case-insensitive). Every syntax error is a
:class:`~gsr.errors.ParseError` with the line, the column and what was expected there.
"""

from __future__ import annotations

import re
from functools import cache
from typing import TYPE_CHECKING

from gsr.errors import ParseError
from gsr.pddl.model import Atom
from gsr.step import Step

if TYPE_CHECKING:
    from lark import Lark, Tree
    from lark.exceptions import UnexpectedInput

# The terminals that the fast path below shares with the grammar (one definition of each).
_NAME = r"[A-Za-z0-9_][A-Za-z0-9_\-.\/@#]*"  # starts with a letter, digit or _: "-(" is a delete sign
_PLAN_NAME = r"[A-Za-z0-9_\-.\/@#?]+"
_TIMESTAMP = r"[0-9]+(\.[0-9]+)?[ \t]*:"
_DURATION = r"\[[ \t]*[0-9]+(\.[0-9]+)?[ \t]*\]"

# Kept inline (not a .lark file) so the grammar ships with the module without package-data rules.
STEP_GRAMMAR = rf"""
// a reasoner's step line: list marker, action, claimed effects
step: marker? call effect*

marker: BULLET
      | MINUS
      | INT MARK
      | STEP_WORD INT? ":"

call: "(" NAME NAME* ")"
effect: PLUS atom   -> add
      | MINUS atom  -> delete
atom: "(" NAME NAME* ")"

// an IPC plan line: timestamp, action, duration; no effects
plan_step: TIMESTAMP? plan_call DURATION?
plan_call: "(" PLAN_NAME PLAN_NAME* ")"

BULLET: "*" | "\u2022"
MARK: "." | ")" | ":"
STEP_WORD: /step/i
PLUS: "+"
MINUS: "-"
INT: /[0-9]+/
TIMESTAMP: /{_TIMESTAMP}/
DURATION: /{_DURATION}/
NAME: /{_NAME}/
PLAN_NAME: /{_PLAN_NAME}/

%import common.WS_INLINE
%ignore WS_INLINE
"""

# The most common line, a bare action (with a plan's timestamp and duration), read without lark: the
# same terminals, and lark's ignored whitespace (spaces and tabs); anything else goes to the grammar.
_WS = r"[ \t]*"
_FAST = {
    True: re.compile(rf"{_WS}\({_WS}(?P<names>{_NAME}(?:[ \t]+{_NAME})*){_WS}\){_WS}"),
    False: re.compile(
        rf"{_WS}(?:{_TIMESTAMP})?{_WS}\({_WS}(?P<names>{_PLAN_NAME}(?:[ \t]+{_PLAN_NAME})*){_WS}\){_WS}(?:{_DURATION})?{_WS}"
    ),
}

_WORDS = {
    "NAME": "a name",
    "PLAN_NAME": "a name",
    "INT": "a step number",
    "TIMESTAMP": "a timestamp",
    "DURATION": "a duration",
    "PLUS": "'+'",
    "MINUS": "'-'",
    "LPAR": "'('",
    "RPAR": "')'",
    "BULLET": "a list marker",
    "MARK": "'.'",
    "STEP_WORD": "'step'",
    "COLON": "':'",
    "$END": "end of line",
}


@cache
def _lark(start: str) -> Lark:
    """The parser for one start rule (lark keeps only the terminals that rule can reach)."""
    from lark import Lark

    return Lark(STEP_GRAMMAR, parser="lalr", start=start, maybe_placeholders=False)


def _syntax_error(err: UnexpectedInput, line: str, source: str, lineno: int, effects: bool) -> ParseError:
    """A lark failure as a ParseError at (line, column) with a readable 'expected' list.

    A step line that ends early always gets the ``(missing ')'?)`` hint: reasoner feedback quotes these
    messages, and models were trained on them, so their wording is kept."""
    from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedToken

    if isinstance(err, UnexpectedToken) and err.token.type != "$END":
        found, column, expected = str(err.token), err.column, err.accepts or err.expected
        message = f"unexpected {found!r}"
    elif isinstance(err, UnexpectedCharacters):
        match = re.match(r"[^\s()]+", line[err.pos_in_stream :])
        found = match.group(0) if match else line[err.pos_in_stream]
        column, expected = err.column, err.allowed or set()
        message = f"unexpected {found!r}"
    else:
        column = len(line) + 1
        expected = err.expected if isinstance(err, UnexpectedToken | UnexpectedEOF) else set()
        hint = effects or "RPAR" in expected
        message = "unexpected end of line" + (" (missing ')'?)" if hint else "")
    shown = tuple(sorted({_WORDS.get(name, name) for name in expected}))
    return ParseError(message, source=source, line=lineno, column=column, expected=shown)


def _names(tree: Tree) -> tuple[str, ...]:
    return tuple(str(t).lower() for t in tree.children if not hasattr(t, "data"))


def parse_step_text(
    line: str, source: str = "<step>", lineno: int = 1, effects: bool = True, fast: bool = True
) -> Step:
    """One step line as a Step; ``effects=True`` reads the reasoner's step language (markers, claimed
    effects), ``effects=False`` an IPC plan line (timestamp, duration). ParseError with line and column.
    ``fast`` reads a bare action line with a regular expression of the same terminals instead of lark
    (the same result; ``fast=False`` sends every line through the grammar, which tests compare)."""
    from lark.exceptions import UnexpectedInput

    plain = _FAST[effects].fullmatch(line) if fast else None
    if plain is not None:
        names = tuple(plain.group("names").lower().split())
        return Step(names[0], names[1:])
    try:
        tree = _lark("step" if effects else "plan_step").parse(line)
    except UnexpectedInput as err:
        raise _syntax_error(err, line, source, lineno, effects) from None
    kind = "call" if effects else "plan_call"
    call = next(c for c in tree.children if getattr(c, "data", None) == kind)
    names = _names(call)
    add: list[Atom] = []
    delete: list[Atom] = []
    for child in tree.children:
        if getattr(child, "data", None) in ("add", "delete"):
            atom_names = _names(next(c for c in child.children if hasattr(c, "data")))
            (add if child.data == "add" else delete).append(Atom(atom_names[0], atom_names[1:]))
    if not add and not delete:  # no effect list: the line makes no claim
        return Step(names[0], names[1:])
    return Step(names[0], names[1:], tuple(add), tuple(delete))
