"""`gsr solve` and `gsr reason ...`: the reasoner on the command line (called from gsr.cli).

Exit codes of ``gsr solve``: 0 with a plan that reaches the goal; 1 when no valid plan was found (the
reason is printed: the goal is impossible, the model's output never repaired, the step limit, a backend
failure) or on bad input.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from gsr.diagnosis import formula_text
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.gsr_bench_format import gsr_bench_commands
from gsr.gsr_bench_rules import replay
from gsr.io import load_scene, read_text
from gsr.pddl.model import Domain
from gsr.pddl.parser import load_domain
from gsr.plan_format import write_plan
from gsr.reason.backends import make_backend
from gsr.reason.goal_text import GoalRejected, parse_goal_answer
from gsr.reason.options import SolveOptions
from gsr.reason.prompt import build_goal_prompt, build_prompt
from gsr.reason.reasoner import solve
from gsr.reason.result import ReasonResult
from gsr.reason.step_format import format_step, parse_steps
from gsr.resources import load_builtin_domain
from gsr.validate import validate_plan

FORMATS = ("text", "json", "pddl", "gsr-bench")


def _domain(path: Path | None) -> Domain:
    return load_domain(path) if path is not None else load_builtin_domain()


def _goal(text: str | None, domain: Domain, graph):
    if text is None:
        return None

    try:
        return parse_goal_answer(text, domain, state_from_graph(graph, domain))
    except GoalRejected as exc:
        raise GSRError(f"--goal: {exc}") from None


def render(result: ReasonResult) -> str:
    """Human-readable report: the goal, the checked steps (with who proposed them), the outcome."""
    lines = []
    if result.goal is not None:
        lines.append(f"goal: {formula_text(result.goal.formula)}  ({result.goal_source})")
    for i, s in enumerate(result.steps, 1):
        note = f"{s.source}" + (f", after {len(s.rejected)} rejected" if s.rejected else "")
        lines.append(f"{i}. {format_step(s.step)}    ; {note}")
    counts = result.to_dict()["counts"]
    lines.append(
        f"{result.status}: {result.message} (model calls {counts['model_calls']}, "
        f"rejections {counts['rejections']}, repairs {counts['repairs']}, "
        f"planner takeovers {counts['planner_takeovers']}, {result.seconds:.2f} s)"
    )
    return "\n".join(lines)


def solve_command(
    scene: Path,
    instruction: str,
    options: SolveOptions | None = None,
    *,
    backend: str = "grounder",
    goal: str | None = None,
    domain_file: Path | None = None,
    base_url: str | None = None,
    fmt: str = "text",
    as_json: bool = False,
    transcript: bool = False,
) -> int:
    """Run the reasoner on a scene file; print the checked plan in ``fmt``; return the exit code.

    ``options`` are the loop's settings (mode, step and repair limits, constrained decoding);
    ``backend`` is a backend spec, ``base_url`` its OpenAI-compatible server, ``goal`` a PDDL goal that
    replaces the instruction's; ``as_json`` prints the result as JSON whatever ``fmt`` (which still
    decides the rules a ``gsr-bench`` plan is made under); ``transcript`` adds every prompt and reply
    to JSON output.
    """
    if fmt not in FORMATS:
        raise GSRError(f"unknown --format {fmt!r}: choose one of {', '.join(FORMATS)}")
    options = options or SolveOptions()
    domain = _domain(domain_file)
    graph = load_scene(scene)
    if fmt == "gsr-bench":  # the plan is for GSR-Bench: plan under its rules (see gsr.gsr_bench_rules)
        graph = graph.model_copy(update={"metadata": {**graph.metadata, "rules": "gsr-bench"}})
    settings = {"base_url": base_url} if base_url and backend.startswith("openai:") else {}
    model = make_backend(backend, **settings)
    result = solve(graph, instruction, model, domain=domain, goal=_goal(goal, domain, graph), options=options)
    if as_json or fmt == "json":
        print(json.dumps(result.to_dict(transcript=transcript), indent=2))
    elif fmt == "text" or not result.success:
        print(render(result))
    elif fmt == "pddl":
        print(write_plan(result.plan), end="")
    else:
        print("\n".join(gsr_bench_plan(graph, result.plan)))
    if result.success:
        return 0
    print(f"error: no valid plan ({result.status}): {result.message}", file=sys.stderr)
    for group in result.unrepaired[-1:]:
        for attempt in group[-2:]:
            why = attempt.error or (attempt.diagnosis.message if attempt.diagnosis else "")
            print(f"  rejected {attempt.reply.strip()[:120]!r}: {why}", file=sys.stderr)
    return 1


def gsr_bench_plan(graph, plan) -> list[str]:
    """The plan as GSR-Bench commands, replayed under the benchmark's validator rules (GSRError if rejected)."""
    commands = gsr_bench_commands(plan)
    checked = replay(graph, commands)
    bad = checked.rejected
    if bad is not None:
        rule = bad.rule.value if bad.rule else "?"
        raise GSRError(
            f"GSR-Bench's rules reject command {len(checked.verdicts)} '{bad.command}' ({rule}): {bad.message}"
        )
    return commands


def prompt_command(scene: Path, instruction: str, mode: str, domain_file: Path | None = None) -> int:
    """Print the prompt the reasoner would send for the first step (or the goal)."""
    domain = _domain(domain_file)
    graph = load_scene(scene)
    prompt = (build_goal_prompt if mode == "goal" else build_prompt)(graph, domain, instruction)
    print(prompt.text(), end="")
    return 0


def check_command(scene: Path, steps_file: Path, as_json: bool, domain_file: Path | None = None) -> int:
    """Parse step lines (a model's output) and check them in order against the scene: 0 all valid, 1 not."""
    domain = _domain(domain_file)
    graph = load_scene(scene)
    steps = parse_steps(read_text(steps_file), source=str(steps_file))
    report = validate_plan(domain, state_from_graph(graph, domain), steps)
    print(json.dumps(report.to_dict(), indent=2) if as_json else str(report))
    return 0 if report.valid else 1
