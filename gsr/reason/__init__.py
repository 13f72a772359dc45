"""The LLM reasoner: step language, prompts, the propose-check-repair loop and model backends.

Heavy backends (torch/transformers, httpx) are imported only when a backend is built.
"""

from gsr.reason.applicable import applicable_steps
from gsr.reason.backend import Backend, BackendError, FunctionBackend, Query
from gsr.reason.backends import as_backend, make_backend, register_backend
from gsr.reason.examples import Example, annotate_steps, builtin_example, default_examples
from gsr.reason.goal_text import GoalRejected, parse_goal_answer
from gsr.reason.loop import LoopState, SolveLoop
from gsr.reason.options import MODES, SolveOptions, Status
from gsr.reason.prompt import DONE, Prompt, action_text, build_goal_prompt, build_prompt, predicate_text
from gsr.reason.reasoner import Reasoner, solve
from gsr.reason.result import STATUSES, Attempt, CheckedStep, Exchange, ReasonResult
from gsr.reason.scene_text import scene_text
from gsr.reason.step_format import (
    STEP_GRAMMAR,
    format_step,
    format_steps,
    parse_first_step,
    parse_step_line,
    parse_steps,
    step_from_json,
)

__all__ = [
    "DONE",
    "MODES",
    "STATUSES",
    "STEP_GRAMMAR",
    "Attempt",
    "Backend",
    "BackendError",
    "CheckedStep",
    "Example",
    "Exchange",
    "FunctionBackend",
    "GoalRejected",
    "LoopState",
    "Prompt",
    "Query",
    "ReasonResult",
    "Reasoner",
    "SolveLoop",
    "SolveOptions",
    "Status",
    "action_text",
    "annotate_steps",
    "applicable_steps",
    "as_backend",
    "build_goal_prompt",
    "build_prompt",
    "builtin_example",
    "default_examples",
    "format_step",
    "format_steps",
    "make_backend",
    "parse_first_step",
    "parse_goal_answer",
    "parse_step_line",
    "parse_steps",
    "predicate_text",
    "register_backend",
    "scene_text",
    "solve",
    "step_from_json",
]
