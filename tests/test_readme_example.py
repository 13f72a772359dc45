"""The README's Python example runs, and what its comments say is what it does."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

from gsr.pddl.parser import parse_formula
from gsr.pddl.walk import conjuncts
from gsr.step import Step

README = Path(__file__).resolve().parents[1] / "README.md"


def _example() -> list[str]:
    """The first ```python block of the README, as lines."""
    text = README.read_text(encoding="utf-8")
    match = re.search(r"```python\n(.*?)```", text, re.S)
    assert match, "README.md has no ```python example"
    return match.group(1).splitlines()


def _comment(lines: list[str], startswith: str) -> str:
    line = next(line for line in lines if line.startswith(startswith))
    return line.split("#", 1)[1].strip()


def test_readme_example_runs_and_its_comments_hold() -> None:
    lines = _example()
    namespace: dict = {}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile("\n".join(lines), str(README), "exec"), namespace)
    # the goal comment is the goal the grounder finds (a one-part conjunction reads as its part)
    assert conjuncts(namespace["goal"].formula) == conjuncts(parse_formula(_comment(lines, "goal =")))
    # the solve comment lists the checked steps
    result = namespace["result"]
    said = re.findall(r"\([^()]*\)", _comment(lines, "result ="))
    assert result.success and [str(Step(s.step.action, s.step.args)) for s in result.steps] == said
    # the printed diagnosis is the comment block under the print call
    start = next(i for i, line in enumerate(lines) if line.startswith("print("))
    expected = [line[2:] for line in lines[start + 1 :] if line.startswith("# ")]
    assert out.getvalue().rstrip("\n").splitlines() == expected
