"""IPC plan files: one ``(action arg ...)`` per line, ``;`` comments, optional ``t:`` timestamps."""

from __future__ import annotations

import re
from pathlib import Path

from gsr.errors import GSRError, ParseError
from gsr.step import Plan, Step

_NAME = re.compile(r"[A-Za-z0-9_\-./@#?]+")
_TIMESTAMP = re.compile(r"\s*\d+(?:\.\d+)?\s*:")
_DURATION = re.compile(r"\s*\[\s*\d+(?:\.\d+)?\s*\]")


def _parse_line(line: str, source: str, lineno: int) -> Step | None:
    """One plan line (comment already stripped) to a Step, or None when blank."""
    pos = 0
    stamp = _TIMESTAMP.match(line)
    if stamp:
        pos = stamp.end()

    def error(message: str, at: int, expected: tuple[str, ...] = ()) -> ParseError:
        return ParseError(message, source=source, line=lineno, column=at + 1, expected=expected)

    while pos < len(line) and line[pos].isspace():
        pos += 1
    if pos == len(line):
        if stamp:
            raise error("timestamp without an action", pos, ("'('",))
        return None
    if line[pos] != "(":
        raise error(f"unexpected {line[pos]!r}", pos, ("'('",))
    pos += 1
    names: list[str] = []
    while True:
        while pos < len(line) and line[pos].isspace():
            pos += 1
        if pos == len(line):
            raise error("unclosed '('", pos, ("')'",))
        if line[pos] == ")":
            pos += 1
            break
        match = _NAME.match(line, pos)
        if not match:
            raise error(f"unexpected {line[pos]!r}", pos, ("a name", "')'"))
        names.append(match.group().lower())
        pos = match.end()
    if not names:
        raise error("empty action", pos - 1, ("an action name",))
    duration = _DURATION.match(line, pos)
    if duration:
        pos = duration.end()
    rest = line[pos:].strip()
    if rest:
        raise error(f"unexpected {rest[0]!r} after the action", line.index(rest[0], pos), ("end of line",))
    return Step(names[0], tuple(names[1:]))


def parse_plan(text: str, source: str = "<string>") -> Plan:
    """Parse an IPC plan (case-insensitive; comments, blank lines and timestamps allowed)."""
    steps = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        step = _parse_line(raw.split(";", 1)[0], source, lineno)
        if step is not None:
            steps.append(step)
    return Plan(tuple(steps))


def load_plan(path: str | Path) -> Plan:
    """Read and parse an IPC plan file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise GSRError(f"{path}: cannot read plan file ({exc.strerror or exc})") from None
    return parse_plan(text, source=str(path))


def plan_cost_comment(plan: Plan, cost: float | None = None) -> str:
    """The ``; cost = N (unit cost)`` trailer (``general cost`` when a different cost is given)."""
    if cost is None or float(cost) == float(len(plan)):
        return f"; cost = {len(plan)} (unit cost)"
    return f"; cost = {float(cost):g} (general cost)"


def write_plan(plan: Plan, cost: float | None = None) -> str:
    """The plan in IPC format, one action per line, ending with the cost comment."""
    lines = [str(Step(s.action, s.args)) for s in plan.steps]
    lines.append(plan_cost_comment(plan, cost))
    return "\n".join(lines) + "\n"
