"""The LLM reasoner: step language, prompts, the propose-check-repair loop and model backends.

Heavy backends (torch/transformers, httpx) are imported only when a backend is built.
"""

from gsr.reason.examples import annotate_steps, builtin_example
from gsr.reason.prompt import (
    DONE,
    Example,
    Prompt,
    action_text,
    build_goal_prompt,
    build_prompt,
    default_examples,
    predicate_text,
    scene_text,
)
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
    "STEP_GRAMMAR",
    "Example",
    "Prompt",
    "action_text",
    "annotate_steps",
    "build_goal_prompt",
    "build_prompt",
    "builtin_example",
    "default_examples",
    "format_step",
    "format_steps",
    "parse_first_step",
    "parse_step_line",
    "parse_steps",
    "predicate_text",
    "scene_text",
    "step_from_json",
]
