"""The no-checker baseline: a model's steps go straight to execution (open loop), for ablations.

``gsr bench run tasks --agent gsr.train.openloop:OpenLoopAgent --agent-opt backend=transformers:DIR``
runs a trained model with the reasoner's prompt but *without* the propose-check-repair loop: each
answer is parsed and handed to the executor as is (claimed effects dropped, so only the action is
judged), and the first inapplicable step ends the episode. Goals are resolved like the reasoner does
(embedded grounder, else the model's goal answer). Comparing with ``--agent reasoner`` measures what
the checker buys. Implements the core's episode seam :class:`gsr.episode.Agent`.
"""

from __future__ import annotations

from gsr.diagnosis import Diagnosis
from gsr.errors import GSRError, ParseError
from gsr.facts import state_from_graph
from gsr.language import ground
from gsr.pddl.model import Domain, Formula
from gsr.reason.applicable import applicable_steps
from gsr.reason.backend import Query
from gsr.reason.backends import make_backend
from gsr.reason.goal_text import parse_goal_answer
from gsr.reason.prompt import DONE, build_goal_prompt, build_prompt
from gsr.reason.step_format import format_step, parse_first_step
from gsr.scene_graph import SceneGraph
from gsr.step import Step
from gsr.task_spec import TaskSpec


class OpenLoopAgent:
    """A model proposing steps with no checker between it and the world (a :class:`gsr.episode.Agent`)."""

    name = "open-loop"

    def __init__(
        self, backend: str = "grounder", constrained: bool = False, max_new_tokens: int = 160
    ) -> None:
        if not isinstance(backend, str) or not backend.startswith("transformers:"):
            raise GSRError("OpenLoopAgent: backend must be transformers:PATH")
        self.backend = make_backend(backend)
        self.constrained = bool(constrained)
        self.history: list[Step] = []
        self.goal: Formula | None = None
        self.domain: Domain | None = None
        self.rejected_proposals = 0
        self.believed_goal: Formula | None = None

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Forget the last episode; resolve the goal from the instruction (grounder, else the model)."""
        self.domain = domain
        self.history = []
        self.goal = self._goal(task.initial, task.instruction)
        self.believed_goal = self.goal

    def _goal(self, graph: SceneGraph, instruction: str) -> Formula | None:
        try:
            return ground(instruction, graph, domain=self.domain).formula
        except GSRError:
            pass

        prompt = build_goal_prompt(graph, self.domain, instruction)
        try:
            reply = self.backend.complete(prompt, (), Query("goal", prompt, graph, self.domain, instruction))
        except GSRError:  # a step-only model (compact format) has no goal answer: no goal is shown
            return None
        try:
            return parse_goal_answer(
                reply, self.domain, state_from_graph(graph, self.domain), instruction
            ).formula
        except (
            GSRError
        ):  # GoalRejected and parse errors: no goal shown, as in the reasoner after failed repairs
            return None

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        """The model's next step, unchecked (None when it answers done or nothing parseable)."""
        assert self.domain is not None, "reset() first"
        prompt = build_prompt(graph, self.domain, instruction, history=self.history, goal=self.goal)
        allowed = None
        if self.constrained:
            allowed = (*(format_step(s) for s in applicable_steps(self.domain, graph)), DONE)
        # the structured query goes with every call: compact-format models read it instead of the text
        query = Query(
            "step", prompt, graph, self.domain, instruction, self.goal, tuple(self.history), allowed
        )
        reply = self.backend.complete(prompt, (), query)
        try:
            step = parse_first_step(reply, source="reply")
        except ParseError:
            return None  # an unparseable answer executes nothing: the episode ends here
        if step.action == "done" and not step.args:
            return None
        self.history.append(step)
        return Step(step.action, step.args)  # effects dropped: no checker compares them
