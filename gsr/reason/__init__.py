"""The LLM reasoner: step language, prompts, the propose-check-repair loop and model backends.

Heavy backends (torch/transformers, httpx) are imported only when a backend is built.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

#: public name -> defining module; a name loads its module on first use, so importing a submodule
#: of gsr.reason does not load the whole package
_EXPORTS = {
    "action_text": "gsr.reason.prompt",
    "annotate_steps": "gsr.reason.examples",
    "applicable_steps": "gsr.reason.applicable",
    "as_backend": "gsr.reason.backends",
    "Attempt": "gsr.reason.result",
    "Backend": "gsr.reason.backend",
    "BackendError": "gsr.reason.backend",
    "build_goal_prompt": "gsr.reason.prompt",
    "build_prompt": "gsr.reason.prompt",
    "builtin_example": "gsr.reason.examples",
    "CheckedStep": "gsr.reason.result",
    "default_examples": "gsr.reason.examples",
    "DONE": "gsr.reason.prompt",
    "Example": "gsr.reason.examples",
    "Exchange": "gsr.reason.result",
    "format_step": "gsr.reason.step_format",
    "format_steps": "gsr.reason.step_format",
    "FunctionBackend": "gsr.reason.backend",
    "GoalRejected": "gsr.reason.goal_text",
    "LoopState": "gsr.reason.loop",
    "make_backend": "gsr.reason.backends",
    "MODES": "gsr.reason.options",
    "parse_first_step": "gsr.reason.step_format",
    "parse_goal_answer": "gsr.reason.goal_text",
    "parse_step_line": "gsr.reason.step_format",
    "parse_steps": "gsr.reason.step_format",
    "predicate_text": "gsr.reason.prompt",
    "Prompt": "gsr.reason.prompt",
    "Query": "gsr.reason.backend",
    "Reasoner": "gsr.reason.reasoner",
    "ReasonResult": "gsr.reason.result",
    "register_backend": "gsr.reason.backends",
    "scene_text": "gsr.reason.scene_text",
    "solve": "gsr.reason.reasoner",
    "SolveLoop": "gsr.reason.loop",
    "SolveOptions": "gsr.reason.options",
    "Status": "gsr.reason.options",
    "STATUSES": "gsr.reason.result",
    "step_from_json": "gsr.reason.step_format",
    "STEP_GRAMMAR": "gsr.reason.step_format",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.reason", _EXPORTS, globals())
