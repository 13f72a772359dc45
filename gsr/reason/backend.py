"""The model backend protocol: ``Backend``, ``PlanProposer``, ``Query`` and the backend errors.

A backend answers one prompt at a time. Any object with
``complete(prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str`` is a
backend; a plain function ``str -> str`` is wrapped by ``gsr.reason.backends.as_backend`` (it gets ``prompt.text()``).
``query`` carries the structured request (scene graph, domain, goal, the answers already rejected for
this step, and for constrained decoding the step lines allowed now) for backends that use it; text-only models ignore it.
The backends themselves import this module; specs (``grounder``, ``transformers:PATH``, ``openai:MODEL``)
become backends in :mod:`gsr.reason.backends`, the registry.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from gsr.errors import GSRError
from gsr.pddl.model import Domain
from gsr.reason.prompt import Prompt
from gsr.scene_graph import SceneGraph
from gsr.step import Goal, Step


class BackendError(GSRError):
    """A backend failed to answer (unreachable server, bad model path, no plan for the grounder)."""


class GoalUnreachable(BackendError):
    """The grounder backend's planner proves the goal unreachable from the current scene."""


@runtime_checkable
class PlanProposer(Protocol):
    """A backend that proposes whole step sequences as ``Step`` objects, not text: the loop asks it once,
    checks and applies its steps in order, and asks again only after a rejection (or when the sequence
    ends before the goal holds). No prompt is built and no step goes through text (the embedded
    grounder's planner is one; language models answer through :meth:`Backend.complete`)."""

    def propose_plan(self, domain: Domain, graph: SceneGraph, goal: Goal) -> list[Step]:
        """Steps from ``graph`` towards ``goal`` (empty when it holds); GoalUnreachable / BackendError."""
        ...


@dataclass(frozen=True)
class Query:
    """What the reasoner asks: ``kind`` is ``step`` or ``goal``; ``allowed`` lists admissible step lines."""

    kind: str
    prompt: Prompt
    graph: SceneGraph
    domain: Domain
    instruction: str
    goal: Goal | None = None
    history: tuple[Step, ...] = ()
    allowed: tuple[str, ...] | None = None
    rejected: tuple[str, ...] = ()  # answers the checker already rejected for this step


@runtime_checkable
class Backend(Protocol):
    """A model that completes prompts."""

    name: str

    def complete(self, prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str:
        """The model's answer to ``prompt``."""
        ...


class FunctionBackend:
    """Wraps a function ``prompt text -> answer`` (tests, scripted replies, custom clients)."""

    def __init__(self, fn: Callable[[str], str], name: str = "function") -> None:
        self.fn = fn
        self.name = name

    def complete(self, prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str:
        """Call the function on the plain prompt text."""
        return self.fn(prompt.text())
