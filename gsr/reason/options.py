"""The reasoner's typed settings (:class:`SolveOptions`) and run outcomes (:class:`Status`).

One frozen options object travels from the CLI, the service and the benchmark agents into the loop,
instead of loose keyword arguments and an untyped dict. Statuses are a ``StrEnum``: each member *is*
its string (``Status.SOLVED == "solved"``, ``json.dumps`` and f-strings give ``solved``), so JSON
output and the HTTP API read exactly as they did when statuses were plain strings.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING

from gsr.errors import GSRError

if TYPE_CHECKING:
    from gsr.reason.examples import Example

MODES = ("steps", "goal", "hybrid")


class Status(StrEnum):
    """How a reasoner run ended; only ``SOLVED`` is a success."""

    SOLVED = "solved"  # the goal holds after the checked steps
    DONE_UNVERIFIED = "done_unverified"  # the model said (done) and no goal was known to verify it
    STEP_LIMIT = "step_limit"  # max_steps checked steps without reaching the goal
    STUCK = "stuck"  # no valid step after the allowed repairs (steps mode)
    NO_GOAL = "no_goal"  # goal mode: no acceptable goal after the allowed repairs
    UNSOLVABLE = "unsolvable"  # the planner could not reach the goal (goal or hybrid mode)
    BACKEND_ERROR = "backend_error"  # the backend failed (unreachable server, grounder could not ground)


@dataclass(frozen=True)
class SolveOptions:
    """How the reasoner loop runs (see :mod:`gsr.reason.loop` for the modes).

    ``examples`` are the few-shot examples of language-model prompts (None: the built-in ones);
    ``constrained`` restricts a model's answers to applicable step lines; ``require_effects`` rejects
    step lines that claim no effects; ``show_goal`` puts the resolved goal into step prompts;
    ``prompt_actions`` is how prompts list the actions (``pddl`` or ``compact``); ``planner`` and
    ``planner_timeout`` are used wherever the loop plans (goal mode, hybrid takeovers).
    """

    mode: str = "steps"
    max_steps: int = 40
    max_repairs: int = 3
    constrained: bool = False
    require_effects: bool = False
    show_goal: bool = True
    prompt_actions: str = "pddl"
    planner: str = "lazy-ff"
    planner_timeout: float = 30.0
    examples: Sequence[Example] | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise GSRError(f"unknown mode {self.mode!r}: choose one of {', '.join(MODES)}")
        if self.max_steps < 0 or self.max_repairs < 0:
            raise GSRError("max_steps and max_repairs must be >= 0")
