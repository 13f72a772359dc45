"""IPC plan files: one ``(action arg ...)`` per line, ``;`` comments, optional ``t:`` timestamps.

A line is read by the one step grammar (:mod:`gsr.step_grammar`) with effects off."""

from __future__ import annotations

from pathlib import Path

from gsr.errors import GSRError
from gsr.step import Plan, Step
from gsr.step_grammar import parse_step_text


def _parse_line(line: str, source: str, lineno: int) -> Step | None:
    """One plan line (comment already stripped) to a Step, or None when blank."""
    if not line.strip():
        return None
    return parse_step_text(line, source, lineno, effects=False)


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
    except UnicodeDecodeError as exc:
        raise GSRError(
            f"{path}: cannot read plan file (not UTF-8 text: {exc.reason} at byte {exc.start})"
        ) from None
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
