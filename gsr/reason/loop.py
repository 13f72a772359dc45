"""The reasoner loop: propose, check, repair, advance — in ``steps``, ``goal`` or ``hybrid`` mode.

steps:  the model proposes every step; the checker validates it against the domain and the current
        graph; a rejected answer goes back with the diagnosis (up to ``max_repairs`` times); an accepted
        step advances the graph. Stops when the goal holds, at ``max_steps``, or when the model is stuck.
goal:   the model answers a PDDL goal (checked against the domain and scene, repaired the same way);
        the planner sequences it and every planned step is checked and applied.
hybrid: as steps, but when the model is stuck (no valid step after the repairs, or it revisits a
        state) the planner takes over from the current graph.

A backend that proposes ``Step`` sequences (:class:`~gsr.reason.backend.PlanProposer`, the embedded
grounder) is asked once for a plan whose steps are checked in order; it is asked again only after a
rejection. One :class:`SolveLoop` is one run; its :class:`LoopState` holds what the run carries from
step to step. :mod:`gsr.reason.reasoner` holds the entry points (``solve`` and the closed-loop
``Reasoner``).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

from gsr.check import check_step
from gsr.errors import GSRError, ParseError
from gsr.facts import graph_with_state, state_from_graph
from gsr.language import ground
from gsr.pddl.model import Domain
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.reason.applicable import applicable_steps
from gsr.reason.backend import Backend, BackendError, GoalUnreachable, PlanProposer, Query
from gsr.reason.examples import claimed_effects
from gsr.reason.goal_text import GoalRejected, parse_goal_answer
from gsr.reason.options import MODES, SolveOptions, Status
from gsr.reason.prompt import DONE, Prompt, build_goal_prompt, build_prompt
from gsr.reason.result import Attempt, CheckedStep, Exchange, ReasonResult
from gsr.reason.step_format import format_step, parse_first_step
from gsr.scene_graph import SceneGraph
from gsr.semantics import goal_holds
from gsr.step import Goal, Step
from gsr.validate import explain_goal

__all__ = ["FORMAT_REMINDER", "MODES", "LoopState", "SolveLoop"]

FORMAT_REMINDER = "answer one step line such as (pick red_cube1 table) +(holding red_cube1) -(hand_empty) -(on red_cube1 table)"


@dataclass
class LoopState:
    """What one run carries from step to step: the current graph, the result being built, how often
    each state was visited, the proposer's remaining plan and the answers rejected for the next step."""

    graph: SceneGraph
    result: ReasonResult
    seen: Counter[frozenset] = field(default_factory=Counter)  # visits of each state (atoms)
    pending: list[Step] = field(default_factory=list)  # a PlanProposer's steps not yet checked
    rejected: list[Attempt] = field(default_factory=list)  # answers rejected for the step now sought


class SolveLoop:
    """One solve: the backend, domain, instruction and options it runs with, and its :class:`LoopState`."""

    def __init__(
        self, backend: Backend, domain: Domain, graph: SceneGraph, instruction: str, options: SolveOptions
    ) -> None:
        self.backend = backend
        self.domain = domain
        self.instruction = instruction
        self.options = options
        name = getattr(backend, "name", type(backend).__name__)
        self.state = LoopState(graph, ReasonResult(instruction, options.mode, name))

    @property
    def graph(self) -> SceneGraph:
        return self.state.graph

    @property
    def result(self) -> ReasonResult:
        return self.state.result

    # ---------------------------------------------------------------- model calls

    def allowed_steps(self, goal: Goal | None) -> tuple[str, ...]:
        """Constrained decoding's admissible lines: the applicable steps whose next state this episode
        has visited least often (never visited, when there are such), so a model cannot loop between
        states while another way is open; ``(done)`` too when no goal can verify completion."""

        state = state_from_graph(self.graph, self.domain)
        steps = applicable_steps(self.domain, self.graph)
        visits = [self.state.seen[check_step(self.domain, state, s).next_state.atoms] for s in steps]
        least = min(visits, default=0)
        allowed = tuple(format_step(s) for s, v in zip(steps, visits, strict=True) if v == least)
        if goal is None:  # with no goal to verify, the model must be able to say it is done
            allowed += (DONE,)
        return allowed

    def ask(
        self,
        kind: str,
        prompt: Prompt,
        goal: Goal | None,
        history: Sequence[Step],
        rejected: Sequence[str] = (),
    ) -> str:
        """One backend call, recorded in the transcript; a backend crash becomes BackendError."""
        allowed = self.allowed_steps(goal) if kind == "step" and self.options.constrained else None
        query = Query(
            kind,
            prompt,
            self.graph,
            self.domain,
            self.instruction,
            goal,
            tuple(history),
            allowed,
            tuple(rejected),
        )
        start = time.perf_counter()
        try:
            reply = self.backend.complete(prompt, (), query)
        except BackendError:
            raise
        except Exception as exc:  # a model, client or grounder failure must not crash the loop: report it
            raise BackendError(f"backend {self.result.backend} failed: {type(exc).__name__}: {exc}") from None
        if not isinstance(reply, str):
            raise BackendError(f"backend {self.result.backend} returned {type(reply).__name__}, not text")
        self.result.transcript.append(Exchange(kind, prompt, reply, time.perf_counter() - start))
        return reply

    # ---------------------------------------------------------------- goal

    def model_goal(self) -> Goal | None:
        """Ask the model for the goal, repairing bad answers; None when none is acceptable."""

        o = self.options
        state = state_from_graph(self.graph, self.domain)
        rejected: list[tuple[str, str]] = []
        for _ in range(1 + o.max_repairs):
            prompt = build_goal_prompt(self.graph, self.domain, self.instruction, o.examples, rejected)
            reply = self.ask("goal", prompt, None, ())
            try:
                goal = parse_goal_answer(reply, self.domain, state, self.instruction)
            except GoalRejected as exc:
                self.result.goal_attempts.append(Attempt(reply, error=str(exc)))
                rejected.append((reply, str(exc)))
                continue
            if o.mode == "goal":  # the planner must be able to reach it
                found = plan_api.plan_graph(self.domain, self.graph, goal, o.planner, o.planner_timeout)
                if not found.solved:
                    why = f"the planner cannot reach this goal ({found.status}): {found.message}"
                    self.result.goal_attempts.append(Attempt(reply, error=why))
                    rejected.append((reply, why))
                    continue
            self.result.goal_attempts.append(Attempt(reply))
            return goal
        return None

    def resolve_goal(self, goal: Goal | None) -> Goal | None:
        """The goal to reach: given, else the embedded grounder's, else the model's (goal prompt)."""
        if goal is not None:
            self.result.goal_source = "given"
            return goal
        if self.options.mode != "goal" or self.result.backend == "grounder":
            try:
                found = ground(self.instruction, self.graph, domain=self.domain)
                self.result.goal_source = "grounder"
                return found
            except ImportError:
                pass
            except GSRError as exc:
                if self.result.backend == "grounder":
                    raise BackendError(f"the grounder cannot interpret the instruction: {exc}") from None
        found = self.model_goal()
        if found is not None:
            self.result.goal_source = "model"
        return found

    # ---------------------------------------------------------------- steps

    def goal_holds(self, goal: Goal | None) -> bool:

        return goal is not None and goal_holds(self.domain, goal, state_from_graph(self.graph, self.domain))

    def accept(self, step: Step, diagnosis, source: str, rejected: Sequence[Attempt]) -> None:

        self.result.steps.append(CheckedStep(step, diagnosis, source, tuple(rejected)))
        self.state.graph = graph_with_state(self.graph, diagnosis.next_state)

    def judge(self, reply: str, goal: Goal | None) -> tuple[Attempt, bool]:
        """Parse and check one step answer: (attempt, the model claims it is done)."""

        try:
            step = parse_first_step(reply, source="reply")
        except ParseError as exc:
            return Attempt(reply, error=f"cannot parse the step: {exc}; {FORMAT_REMINDER}"), False
        state = state_from_graph(self.graph, self.domain)
        if step.action == "done" and not step.args and "done" not in self.domain.actions:
            if goal is None:
                return Attempt(reply, step), True
            reasons, hints = explain_goal(self.domain, goal, state)
            why = "; ".join(r.detail for r in reasons[:3]) + "".join(f"; hint: {h}" for h in hints[:2])
            return Attempt(reply, step, error=f"the goal does not hold yet: {why}"), False
        if self.options.require_effects and not step.claims_effects:
            return Attempt(reply, step, error=f"the step claims no effects; {FORMAT_REMINDER}"), False
        return Attempt(reply, step, check_step(self.domain, state, step)), False

    def planner_takeover(self, goal: Goal | None, why: str) -> None:
        """Sequence the rest with the planner from the current graph; every step is checked."""

        o = self.options
        self.result.planner_takeovers += 1
        if goal is None:
            self.finish(Status.STUCK, f"{why}; no goal is known, so the planner cannot take over")
            return
        found = plan_api.plan_graph(self.domain, self.graph, goal, o.planner, o.planner_timeout)
        if not found.solved or found.plan is None:
            self.finish(
                Status.UNSOLVABLE, f"{why}; the planner found no plan ({found.status}): {found.message}"
            )
            return
        for step in found.plan.steps:
            if len(self.result.steps) >= o.max_steps:
                break
            diagnosis = check_step(self.domain, state_from_graph(self.graph, self.domain), step)
            if not diagnosis.ok:  # cannot happen with a sound planner: report rather than execute
                self.finish(Status.UNSOLVABLE, f"planner step rejected by the checker: {diagnosis.message}")
                return
            self.accept(step, diagnosis, "planner", ())

    def run_proposed(self, proposer: PlanProposer, goal: Goal) -> None:
        """The loop for a backend that proposes ``Step`` sequences: one call gives the plan, whose steps
        are checked and applied in order; a rejected step (or a plan that ends short of the goal) asks
        again from the current graph, at most ``max_repairs`` times in a row."""

        s = self.state
        while len(self.result.steps) < self.options.max_steps:
            if self.goal_holds(goal):
                self.finish(Status.SOLVED, f"goal reached after {len(self.result.steps)} step(s)")
                return
            if not s.pending:
                if len(s.rejected) > self.options.max_repairs:
                    self.result.unrepaired.append(tuple(s.rejected))
                    last = s.rejected[-1]
                    why = last.error or (last.diagnosis.message if last.diagnosis else "rejected")
                    self.finish(Status.STUCK, f"no valid step after {len(s.rejected)} proposal(s): {why}")
                    return
                s.pending = proposer.propose_plan(self.domain, self.graph, goal)
                if not s.pending:  # the proposer sees the goal as reached, the checker does not
                    s.rejected.append(Attempt("(done)", error="the proposer ended before the goal holds"))
                    continue
            step = s.pending.pop(0)
            state = state_from_graph(self.graph, self.domain)
            diagnosis = check_step(self.domain, state, step)
            if not diagnosis.ok:
                s.rejected.append(Attempt(str(step), step, diagnosis))
                s.pending = []
                continue
            # recorded with the change it makes, as a model's step line would claim it
            self.accept(claimed_effects(diagnosis, state), diagnosis, "model", s.rejected)
            s.rejected = []
        self.finish_at_limit(goal)

    def run_steps(self, goal: Goal | None) -> None:
        """The propose-check-repair loop."""

        o = self.options
        if isinstance(self.backend, PlanProposer) and goal is not None and not o.constrained:
            self.run_proposed(self.backend, goal)
            return
        seen = self.state.seen
        seen[state_from_graph(self.graph, self.domain).atoms] += 1
        while len(self.result.steps) < o.max_steps:
            if self.goal_holds(goal):
                self.finish(Status.SOLVED, f"goal reached after {len(self.result.steps)} step(s)")
                return
            rejected = self.state.rejected = []
            accepted = False
            for _ in range(1 + o.max_repairs):
                history = [s.step for s in self.result.steps]
                feedback = [(a.reply, a.error or str(a.diagnosis)) for a in rejected]
                shown_goal = goal if o.show_goal else None
                prompt = build_prompt(
                    self.graph,
                    self.domain,
                    self.instruction,
                    o.examples,
                    history,
                    feedback,
                    shown_goal,
                    o.prompt_actions,
                )
                reply = self.ask("step", prompt, goal, history, [a.reply for a in rejected])
                attempt, done = self.judge(reply, goal)
                if done:
                    self.finish(
                        Status.DONE_UNVERIFIED, "the model says the instruction is done (no goal to verify)"
                    )
                    return
                if attempt.ok:
                    assert attempt.step is not None and attempt.diagnosis is not None
                    self.accept(attempt.step, attempt.diagnosis, "model", rejected)
                    accepted = True
                    break
                rejected.append(attempt)
            if not accepted:
                self.result.unrepaired.append(tuple(rejected))
                why = f"no valid step after {len(rejected)} answer(s)"
                if o.mode == "hybrid":
                    self.planner_takeover(goal, why)
                    break
                self.finish(Status.STUCK, f"{why}: {rejected[-1].error or rejected[-1].diagnosis.message}")
                return
            atoms = state_from_graph(self.graph, self.domain).atoms
            if atoms in seen and o.mode == "hybrid":
                self.planner_takeover(goal, "the model returned to an earlier state")
                break
            seen[atoms] += 1
        if self.result.status in (Status.STUCK, Status.UNSOLVABLE):
            return
        self.finish_at_limit(goal)

    def run_goal_mode(self, goal: Goal | None) -> None:
        """Goal mode: the planner sequences the model's (or the given) goal; every step is checked."""
        if goal is None:
            n = len(self.result.goal_attempts)
            self.finish(Status.NO_GOAL, f"no acceptable goal after {n} answer(s)")
            return
        self.planner_takeover(goal, "goal mode")
        self.result.planner_takeovers = 0  # sequencing is the mode itself, not a takeover
        if self.result.status != Status.UNSOLVABLE:
            ok = self.goal_holds(goal)
            self.finish(Status.SOLVED if ok else Status.STEP_LIMIT, "goal reached" if ok else "step limit")

    def finish_at_limit(self, goal: Goal | None) -> None:
        """The end of the step budget: solved when the goal holds, else the step limit."""
        if self.goal_holds(goal):
            self.finish(Status.SOLVED, f"goal reached after {len(self.result.steps)} step(s)")
        else:
            self.finish(Status.STEP_LIMIT, f"goal not reached within {self.options.max_steps} step(s)")

    def finish(self, status: Status, message: str) -> None:
        self.result.status = status
        self.result.message = message

    def run(self, goal: Goal | None) -> ReasonResult:
        """Resolve the goal, run the mode's loop; backend failures end the run with their status."""
        start = time.perf_counter()
        try:
            found = self.resolve_goal(goal)
            self.result.goal = found
            if self.options.mode == "goal":
                self.run_goal_mode(found)
            else:
                self.run_steps(found)
        except GoalUnreachable as exc:
            self.finish(Status.UNSOLVABLE, str(exc))
        except BackendError as exc:
            self.finish(Status.BACKEND_ERROR, str(exc))
        self.result.final_graph = self.graph
        self.result.seconds = time.perf_counter() - start
        return self.result
