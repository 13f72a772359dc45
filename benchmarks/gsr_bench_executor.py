"""Symbolic execution under GSR-Bench's own rules: every move/open/close is also judged by its validator's rules.

The tabletop domain checks each step (``pick``, ``place_in`` ...); GSR-Bench has no bare pick, so a
``pick`` followed by the placement of the same object is one ``move X in|on Y`` command, judged by
:func:`gsr.gsr_bench_rules.check_command` on the benchmark's scene graph *before* the pick (where the
benchmark sees it). A command the rules reject rejects the placing step with a ``rule_violation``
reason naming the rule. Actions GSR-Bench does not have (turn on, press, push) are rejected too.
"""

from __future__ import annotations

from gsr.diagnosis import Diagnosis, Reason, ReasonKind
from gsr.gsr_bench_rules import Command, Verdict, check_command, transition
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.symbolic_executor import SymbolicExecutor
from gsr.task_spec import TaskSpec

#: Suites whose episodes run under GSR-Bench's rules.
GSR_BENCH_SUITES = frozenset({"gsr-bench", "gsr-bench-gen"})
_PLACEMENTS = {"place_in": "in", "place_on": "on", "stack": "on"}


def _violation(step: Step, verdict: Verdict) -> Diagnosis:
    rule = verdict.rule.value if verdict.rule else "unparsable_command"
    detail = f"GSR-Bench rejects '{verdict.command}' ({rule}): {verdict.message}"
    reason = Reason(ReasonKind.RULE_VIOLATION, detail, rule=rule)
    return Diagnosis(False, step, (reason,), f"{step}: {detail}", ())


class GSRBenchExecutor(SymbolicExecutor):
    """The symbolic executor with GSR-Bench's validator rules on every command."""

    def __init__(self) -> None:
        super().__init__()
        self.bench: SceneGraph | None = None
        self.held: str | None = None
        self.commands: list[str] = []

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """The task's initial state; the benchmark's view starts as the initial graph."""
        self.bench, self.held, self.commands = task.initial, None, []
        return super().reset(task, domain)

    def execute(self, step: Step) -> Diagnosis:
        """Domain check, then (for a completed move, open or close) the GSR-Bench rules."""
        assert self.bench is not None
        command: Command | None = None
        if step.action == "pick" and step.args:
            pass  # judged with its placement
        elif step.action in _PLACEMENTS and len(step.args) == 2 and step.args[0] == self.held:
            command = Command("move", step.args[0], _PLACEMENTS[step.action], step.args[1])
        elif step.action in ("open", "close") and len(step.args) == 1:
            command = Command(step.action, step.args[0])
        else:
            verdict = Verdict(False, str(step), None, "not one of GSR-Bench's actions (move, open, close)")
            return _violation(step, verdict)
        if command is not None:
            verdict = check_command(self.bench, command)
            if not verdict.ok:
                return _violation(step, verdict)
        diagnosis = super().execute(step)
        if not diagnosis.ok:
            return diagnosis
        if step.action == "pick":
            self.held = step.args[0]
        elif command is not None:
            self.bench = transition(self.bench, command)
            self.commands.append(str(command))
            self.held = None
        return diagnosis
