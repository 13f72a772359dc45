"""Answering a step query with a compact-format model (:mod:`gsr.reason.compact`).

Free decoding is greedy over the whole vocabulary; when the checker already rejected that answer for
this step, a small beam search returns the best finished answer not rejected yet (so a repair round
gets the model's next best answer rather than the same one again). Constrained decoding ranks the admissible step lines
exactly: each one is scored by the model's log-probability of its answer tokens (one batched forward
pass) and the best is returned, with its true effects. torch is imported by the caller's backend.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from gsr.errors import ParseError
from gsr.facts import state_from_graph
from gsr.pddl.model import And, Atom, Formula, Not
from gsr.reason.compact import (
    EOS,
    UNK,
    CompactError,
    action_tokens,
    answer_step,
    ground_goal,
    query_tokens,
)
from gsr.reason.prompt import DONE
from gsr.reason.step_format import format_step, parse_first_step
from gsr.semantics import holds
from gsr.step import Step

BEAM = 4
MAX_ANSWER_TOKENS = 6
MAX_UNKNOWN = 3  # distinct unknown context words tolerated (as <unk>)


def _text(step: Step | None) -> str:
    return DONE if step is None else format_step(step)


def answer_key(text: str) -> tuple[str, tuple[str, ...]] | None:
    """An answer's (action, args), ignoring claimed effects; None when it does not parse."""
    try:
        step = parse_first_step(text, source="reply")
    except ParseError:
        return None
    return step.action, step.args


GOAL_ORDERS = ("goal", "dependencies")  # the orders in which open goal literals enter a goal window


def _after(p: Formula, q: Formula) -> bool:
    """Whether goal literal ``p`` waits for ``q`` in the dependency order: a negative literal waits for
    every positive one (closing or switching off comes last: reaching a positive literal may need the
    container open again), and a positive literal waits for a positive one that moves the object ``p``
    puts something on or in (``(on a b)`` after ``(in b c)``: the base is placed first)."""
    if isinstance(p, Not):
        return not isinstance(q, Not)
    if isinstance(q, Not) or not isinstance(p, Atom) or not isinstance(q, Atom) or not q.args:
        return False
    return q.args[0] in p.args[1:]


def dependency_order(literals: Sequence[Formula]) -> list[Formula]:
    """``literals`` (goal literals) with each one after the literals it waits for (:func:`_after`); ties
    and cycles keep the goal's order. Read from the goal alone, so the order does not change as the state
    does (a window whose order moved with the state could hide the literal the model is working on)."""
    rest, out = list(literals), []
    while rest:
        pick = next((p for p in rest if not any(q is not p and _after(p, q) for q in rest)), rest[0])
        out.append(pick)
        rest.remove(pick)
    return out


def window_goal(formula: Formula, graph: Any, domain: Any, limit: int, order: str = "goal") -> Formula:
    """Goal serialisation for a model trained on short goals: when the grounded goal is a conjunction of
    literals of which more than ``limit`` do not hold in ``graph``'s state, the goal the model is shown
    keeps every literal that holds (so the model sees what not to undo) and only the first ``limit``
    that do not, in the goal's order (``order="goal"``) or in :func:`dependency_order` over the whole
    goal (``"dependencies"``), listed in the goal's order; otherwise ``formula`` unchanged. The episode
    still runs until the whole goal holds: as shown literals come true, the next ones enter the window."""
    if order not in GOAL_ORDERS:
        raise ValueError(f"goal order {order!r} is not one of {', '.join(GOAL_ORDERS)}")
    state = state_from_graph(graph, domain)
    grounded = ground_goal(formula, state, domain)
    parts = grounded.parts if isinstance(grounded, And) else (grounded,)
    if not all(isinstance(p, Atom) or (isinstance(p, Not) and isinstance(p.formula, Atom)) for p in parts):
        return formula
    ranked = dependency_order(parts) if order == "dependencies" else parts
    open_parts = [p for p in ranked if not holds(domain, p, state)]
    if len(open_parts) <= limit:
        return formula
    hidden = set(open_parts[limit:]).difference(open_parts[:limit])  # (a literal may repeat)
    return And(tuple(p for p in parts if p not in hidden))


class CompactAnswerer:
    """A loaded compact-format causal LM that answers :class:`gsr.reason.backend.Query` objects.

    ``goal_window`` (None: off) shows the model at most that many goal literals that do not hold yet
    (:func:`window_goal`), the most its training rows had; ``goal_order`` is the order in which open
    literals enter the window (:data:`GOAL_ORDERS`)."""

    def __init__(
        self,
        model: Any,
        tokenizer: Any,
        device: str = "cpu",
        version: int = 1,
        goal_window: int | None = None,
        goal_order: str = "goal",
    ) -> None:
        if goal_order not in GOAL_ORDERS:
            raise CompactError(f"goal order {goal_order!r} is not one of {', '.join(GOAL_ORDERS)}")
        self.version = version  # the compact format version the model was trained in
        self.goal_window = goal_window
        self.goal_order = goal_order
        self.model = model
        self.tokenizer = tokenizer
        self.device = device
        self.eos = tokenizer.convert_tokens_to_ids(EOS)
        self.vocab = tokenizer.get_vocab()

    def ids(self, tokens: Sequence[str], context: bool = False) -> list[int]:
        """Token ids. In a context, a few words the model never saw (a predicate added to the domain
        since training) become ``<unk>``; otherwise an unknown word is a CompactError."""
        missing = sorted({t for t in tokens if t not in self.vocab})
        if missing and (not context or len(missing) > MAX_UNKNOWN):
            raise CompactError(f"the model's vocabulary lacks {', '.join(missing[:5])} (another domain?)")
        unk = self.vocab.get(UNK)
        return [self.vocab.get(t, unk) for t in tokens]

    def answer(self, query: Any) -> str:
        """The model's step line for ``query`` (constrained to ``query.allowed`` when given)."""
        goal = query.goal
        if self.goal_window and goal is not None:
            formula = getattr(goal, "formula", goal)
            goal = window_goal(formula, query.graph, query.domain, self.goal_window, self.goal_order)
        context, naming = query_tokens(query.graph, query.domain, goal, query.history, self.version)
        prompt = self.ids(context, context=True)
        rejected = {k for k in map(answer_key, getattr(query, "rejected", ()) or ()) if k is not None}
        if query.allowed:
            return self._rank(prompt, query, naming, rejected)
        first = self.tokenizer.convert_ids_to_tokens(self.greedy(prompt))
        try:
            step = answer_step(first, naming, query.domain)
            if step is None or (step.action, step.args) not in rejected:
                return _text(step)
        except CompactError:
            if not rejected:
                return " ".join(first)
        for tokens, _score in self._beam(prompt):
            words = self.tokenizer.convert_ids_to_tokens(tokens)
            try:
                step = answer_step(words, naming, query.domain)
            except CompactError:
                continue
            if step is None or (step.action, step.args) not in rejected:
                return _text(step)
        best = self._beam(prompt)
        return " ".join(self.tokenizer.convert_ids_to_tokens(best[0][0])) if best else ""

    def _rank(self, prompt: list[int], query: Any, naming: Any, rejected: set) -> str:
        """The admissible line whose answer tokens the model finds most probable."""
        lines = [line for line in query.allowed if answer_key(line) not in rejected] or list(query.allowed)
        answers = []
        for line in lines:
            key = answer_key(line)
            step = None if key is None or key == ("done", ()) else Step(*key)
            answers.append([*self.ids(action_tokens(step, naming)), self.eos])
        scores = self.score(prompt, answers)
        return lines[max(range(len(lines)), key=scores.__getitem__)]

    def score(self, prompt: list[int], answers: list[list[int]]) -> list[float]:
        """Sum of log-probabilities of each answer after ``prompt`` (one batch)."""
        import torch

        width = len(prompt) + max(len(a) for a in answers)
        pad = self.tokenizer.pad_token_id
        ids = torch.full((len(answers), width), pad, dtype=torch.long)
        mask = torch.zeros_like(ids)
        for i, a in enumerate(answers):
            seq = prompt + a
            ids[i, : len(seq)] = torch.tensor(seq)
            mask[i, : len(seq)] = 1
        with torch.no_grad():
            logp = torch.log_softmax(
                self.model(input_ids=ids.to(self.device), attention_mask=mask.to(self.device)).logits.float(),
                -1,
            ).cpu()
        out = []
        for i, a in enumerate(answers):
            pos = torch.arange(len(prompt) - 1, len(prompt) - 1 + len(a))
            out.append(float(logp[i, pos, torch.tensor(a)].sum()))
        return out

    def greedy(self, prompt: list[int]) -> list[int]:
        """The most probable next token at each position, until ``<eos>``."""
        import torch

        out: list[int] = []
        with torch.no_grad():
            for _ in range(MAX_ANSWER_TOKENS):
                ids = torch.tensor([prompt + out], device=self.device)
                tok = int(self.model(input_ids=ids).logits[0, -1].argmax())
                if tok == self.eos:
                    break
                out.append(tok)
        return out

    def _beam(self, prompt: list[int]) -> list[tuple[list[int], float]]:
        """Finished answers of a width-:data:`BEAM` beam search, best first."""
        import torch

        beams: list[tuple[list[int], float]] = [([], 0.0)]
        done: list[tuple[list[int], float]] = []
        for _ in range(MAX_ANSWER_TOKENS):
            if not beams:
                break
            ids = torch.tensor([prompt + b for b, _ in beams], device=self.device)
            with torch.no_grad():
                logp = torch.log_softmax(self.model(input_ids=ids).logits[:, -1].float(), -1).cpu()
            grown = []
            for (tokens, score), row in zip(beams, logp, strict=True):
                top = torch.topk(row, BEAM)
                for lp, tok in zip(top.values.tolist(), top.indices.tolist(), strict=True):
                    grown.append(([*tokens, tok], score + lp))
            grown.sort(key=lambda b: -b[1])
            beams = []
            for tokens, score in grown:
                if tokens[-1] == self.eos:
                    done.append((tokens[:-1], score))
                elif len(beams) < BEAM:
                    beams.append((tokens, score))
            if len(done) >= BEAM:
                break
        return sorted(done, key=lambda b: -b[1])
