"""Why a step, plan or goal is invalid: the Diagnosis model and the explanation of false formulas.

``explain`` walks a formula that is false in a state and returns one ``Failure`` per false
literal: every failing conjunct of an ``and``, the witness bindings of a failing ``forall``,
"no object satisfies it" for an ``exists``, the failing branches of an ``or``. Negations are
pushed inwards first, so ``(not (and a b))`` is explained as ``(or (not a) (not b))``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from enum import Enum
from functools import cached_property
from typing import Any

from gsr.pddl.model import (
    OBJECT,
    And,
    Atom,
    Equals,
    Exists,
    Forall,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Not,
    Or,
    TypedVar,
    is_variable,
)
from gsr.semantics import CompiledDomain, Fact, fact_atom, successor
from gsr.state import State
from gsr.step import Step

MAX_WITNESSES = 3  # falsifying bindings reported per forall; more are counted, not listed

# Binary predicates that read naturally as "x is <p> y" in messages.
_RELATION_WORDS = {
    "on",
    "in",
    "inside",
    "ontop",
    "under",
    "above",
    "below",
    "at",
    "near",
    "nextto",
    "touching",
    "left_of",
    "right_of",
    "front_of",
    "behind",
    "over",
    "attached",
    "overlaid",
    "carry",
    "holding",
}


class ReasonKind(Enum):
    """What is wrong with a step, plan or goal."""

    UNKNOWN_ACTION = "unknown_action"
    WRONG_ARITY = "wrong_arity"
    TYPE_MISMATCH = "type_mismatch"
    UNKNOWN_OBJECT = "unknown_object"
    UNSATISFIED_PRECONDITION = "unsatisfied_precondition"
    EFFECT_MISMATCH = "effect_mismatch"
    GOAL_UNSATISFIED = "goal_unsatisfied"
    RULE_VIOLATION = "rule_violation"  # a benchmark's own action rule (``rule`` names it), e.g. GSR-Bench's


@dataclass(frozen=True, slots=True)
class Reason:
    """One problem: its kind, a human sentence, the failing literal (PDDL text) and witness bindings.

    ``rule`` names the broken benchmark rule of a ``RULE_VIOLATION`` (``target_blocked`` ...).
    """

    kind: ReasonKind
    detail: str
    literal: str | None = None
    bindings: tuple[tuple[str, str], ...] = ()
    rule: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form."""
        out: dict[str, Any] = {"kind": self.kind.value, "detail": self.detail}
        if self.literal is not None:
            out["literal"] = self.literal
        if self.bindings:
            out["bindings"] = dict(self.bindings)
        if self.rule is not None:
            out["rule"] = self.rule
        return out

    def __str__(self) -> str:
        return self.detail


@dataclass(frozen=True)
class Diagnosis:
    """The verdict on one step: ok, or the reasons it is invalid with a message and repair hints.

    A valid step carries its transition; ``next_state``, ``add`` and ``delete`` are computed
    from it on first access, so that checking stays cheap when only the verdict is needed.
    """

    ok: bool
    step: Step | None = None
    reasons: tuple[Reason, ...] = ()
    message: str = ""
    hints: tuple[str, ...] = ()
    cost: float = 0.0
    transition: tuple[State, tuple[Fact, ...], tuple[Fact, ...]] | None = field(
        default=None, repr=False, compare=False
    )

    @cached_property
    def _effects(self) -> tuple[frozenset[Fact], frozenset[Fact]]:
        if self.transition is None:
            return frozenset(), frozenset()
        adds = frozenset(self.transition[1])
        return adds, frozenset(self.transition[2]) - adds

    @cached_property
    def next_state(self) -> State | None:
        """The state after the step (None unless ok)."""
        if not self.ok or self.transition is None:
            return None
        adds, deletes = self._effects
        return successor(self.transition[0], adds, deletes)

    @property
    def add(self) -> frozenset[Atom]:
        """Atoms the step truly adds (empty when the step is not applicable)."""
        return frozenset(map(fact_atom, self._effects[0]))

    @property
    def delete(self) -> frozenset[Atom]:
        """Atoms the step truly deletes (not counting atoms it also adds)."""
        return frozenset(map(fact_atom, self._effects[1]))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form (true effects included when the step is applicable)."""
        out: dict[str, Any] = {
            "ok": self.ok,
            "step": None if self.step is None else str(self.step),
            "message": self.message,
            "reasons": [r.to_dict() for r in self.reasons],
            "hints": list(self.hints),
        }
        if self.transition is not None:
            out["effects"] = {
                "add": sorted(map(str, self.add)),
                "delete": sorted(map(str, self.delete)),
            }
            out["cost"] = self.cost
        return out

    def __str__(self) -> str:
        lines = [self.message]
        if len(self.reasons) > 1:
            lines.extend(f"  - {r.detail}" for r in self.reasons)
        lines.extend(f"  hint: {h}" for h in self.hints)
        return "\n".join(lines)


# ------------------------------------------------------------ PDDL text


def _ground(term: str, env: dict[str, str]) -> str:
    return env.get(term, term) if is_variable(term) else term


def typed_text(params: tuple[TypedVar, ...]) -> str:
    """``?x - cube ?y`` (``object`` left implicit)."""
    parts = []
    for p in params:
        if p.types == (OBJECT,):
            parts.append(p.name)
        elif len(p.types) == 1:
            parts.append(f"{p.name} - {p.types[0]}")
        else:
            parts.append(f"{p.name} - (either {' '.join(p.types)})")
    return " ".join(parts)


def formula_text(f: Formula, env: dict[str, str] | None = None) -> str:
    """PDDL text of ``f`` with the variables in ``env`` replaced by their objects."""
    env = env or {}
    if isinstance(f, Atom):
        return f"({' '.join((f.predicate, *(_ground(a, env) for a in f.args)))})"
    if isinstance(f, Equals):
        return f"(= {_ground(f.left, env)} {_ground(f.right, env)})"
    if isinstance(f, Not):
        return f"(not {formula_text(f.formula, env)})"
    if isinstance(f, (And, Or)):
        word = "and" if isinstance(f, And) else "or"
        return f"({' '.join((word, *(formula_text(p, env) for p in f.parts)))})"
    if isinstance(f, Imply):
        return f"(imply {formula_text(f.condition, env)} {formula_text(f.then, env)})"
    if isinstance(f, (Exists, Forall)):
        word = "exists" if isinstance(f, Exists) else "forall"
        inner = {k: v for k, v in env.items() if k not in {p.name for p in f.params}}
        return f"({word} ({typed_text(f.params)}) {formula_text(f.body, inner)})"
    if isinstance(f, ForN):
        inner = {k: v for k, v in env.items() if k not in {p.name for p in f.params}}
        return f"(forn ({f.count}) ({typed_text(f.params)}) {formula_text(f.body, inner)})"
    if isinstance(f, ForPairs):
        inner = {k: v for k, v in env.items() if k not in {p.name for p in (*f.first, *f.second)}}
        body = formula_text(f.body, inner)
        return f"(forpairs ({typed_text(f.first)}) ({typed_text(f.second)}) {body})"
    return str(f)


def fact_text(fact: Fact) -> str:
    """``(on a b)`` for the fact tuple ``("on", "a", "b")``."""
    return f"({' '.join(fact)})"


def atom_phrase(fact: Fact) -> str:
    """A short sentence saying that a fact holds: ``blue_box is on red_box``."""
    if len(fact) == 3 and fact[0] in _RELATION_WORDS:
        return f"{fact[1]} is {fact[0].replace('_', ' ')} {fact[2]}"
    return f"{fact_text(fact)} holds"


# ------------------------------------------------------------ explanation


@dataclass(frozen=True, slots=True)
class Failure:
    """A false ground literal (or sub-formula) and why; ``fact``/``wanted`` drive repair hints."""

    literal: str
    why: str
    bindings: tuple[tuple[str, str], ...] = ()
    fact: Fact | None = None
    wanted: bool = True  # True: the fact should hold; False: it should not
    children: tuple[Failure, ...] = ()

    def sentence(self, role: str) -> str:
        """``precondition (clear b) is false: ...`` for role ``precondition``."""
        text = f"{role} {self.literal} is false"
        return f"{text}: {self.why}" if self.why else text


class Explainer:
    """Explains false formulas in one state (compiled evaluation of sub-formulas)."""

    def __init__(self, cd: CompiledDomain, state: State) -> None:
        self.cd = cd
        self.state = state
        self.view = cd.view(state)

    def holds(self, f: Formula, env: dict[str, str]) -> bool:
        """Evaluate ``f`` under ``env``."""
        names = tuple(sorted(env))
        fn = self.cd.formula_fn(f, names)
        if len(self.view[1]) != len(self.cd.slots):  # compiling added a quantifier type
            self.view = self.cd.view(self.state)
        return fn(*self.view, *(env[n] for n in names))

    def typed_objects(self, params: tuple[TypedVar, ...]) -> list[tuple[str, ...]]:
        """Object lists for the quantified parameters."""
        slots = [self.cd.type_slot(p.types) for p in params]
        self.view = self.cd.view(self.state)
        return [self.view[1][s] for s in slots]

    def explain(self, f: Formula, env: dict[str, str]) -> list[Failure]:
        """One Failure per false literal of ``f`` (call only when ``f`` is false under ``env``)."""
        if isinstance(f, Atom):
            fact = (f.predicate, *(_ground(a, env) for a in f.args))
            return [Failure(fact_text(fact), self._instead(fact), fact=fact, wanted=True)]
        if isinstance(f, Equals):
            a, b = _ground(f.left, env), _ground(f.right, env)
            return [Failure(f"(= {a} {b})", f"{a} and {b} are different objects")]
        if isinstance(f, Not):
            return self._explain_not(f.formula, env)
        if isinstance(f, And):
            return [x for p in f.parts if not self.holds(p, env) for x in self.explain(p, env)]
        if isinstance(f, Or):
            children = tuple(x for p in f.parts for x in self.explain(p, env))
            # Branches over static predicates can never change: if one changeable branch is left,
            # it is the literal to report (``(not (and (above ?d x) (open ?d)))`` -> ``(not (open d))``).
            changeable = [c for c in children if c.fact is None or c.fact[0] in self.cd.fluents]
            if len(changeable) == 1 and len(children) > 1:
                return changeable
            why = "no alternative holds: " + "; ".join(c.sentence("").strip() for c in children)
            return [Failure(formula_text(f, env), why if f.parts else "empty disjunction", children=children)]
        if isinstance(f, Imply):
            cond = formula_text(f.condition, env)
            return [
                Failure(
                    x.literal,
                    f"{x.why + '; ' if x.why else ''}required because {cond} holds",
                    x.bindings,
                    x.fact,
                    x.wanted,
                    x.children,
                )
                for x in self.explain(f.then, env)
            ]
        if isinstance(f, Exists):
            kinds = " or ".join(sorted({t for p in f.params for t in p.types}))
            lists = self.typed_objects(f.params)
            why = f"there is no {kinds}" if not all(lists) else f"no {kinds} satisfies it"
            return [Failure(formula_text(f, env), why)]
        if isinstance(f, Forall):
            return self._explain_forall(f, env)
        if isinstance(f, ForN):
            lists = self.typed_objects(f.params)
            names = [p.name for p in f.params]
            count = sum(
                1
                for combo in itertools.product(*lists)
                if self.holds(f.body, {**env, **dict(zip(names, combo, strict=True))})
            )
            why = f"only {count} of the required {f.count} satisfy it"
            return [Failure(formula_text(f, env), why)]
        if isinstance(f, ForPairs):
            return [Failure(formula_text(f, env), "no one-to-one pairing of the objects satisfies it")]
        return [Failure(formula_text(f, env), "is false")]

    def _explain_not(self, g: Formula, env: dict[str, str]) -> list[Failure]:
        if isinstance(g, Atom):
            fact = (g.predicate, *(_ground(a, env) for a in g.args))
            return [Failure(f"(not {fact_text(fact)})", atom_phrase(fact), fact=fact, wanted=False)]
        if isinstance(g, Equals):
            a = _ground(g.left, env)
            return [Failure(f"(not (= {a} {_ground(g.right, env)}))", f"both name {a}")]
        if isinstance(g, Not):
            return self.explain(g.formula, env)
        if isinstance(g, And):
            return self.explain(Or(tuple(Not(p) for p in g.parts)), env)
        if isinstance(g, Or):
            return self.explain(And(tuple(Not(p) for p in g.parts)), env)
        if isinstance(g, Imply):
            return self.explain(And((g.condition, Not(g.then))), env)
        if isinstance(g, Exists):
            return self.explain(Forall(g.params, Not(g.body)), env)
        if isinstance(g, Forall):
            return self.explain(Exists(g.params, Not(g.body)), env)
        return [Failure(formula_text(Not(g), env), "is false")]

    def _explain_forall(self, f: Forall, env: dict[str, str]) -> list[Failure]:
        names = [p.name for p in f.params]
        out: list[Failure] = []
        witnesses = 0
        for combo in itertools.product(*self.typed_objects(f.params)):
            inner = {**env, **dict(zip(names, combo, strict=True))}
            if self.holds(f.body, inner):
                continue
            witnesses += 1
            if witnesses > MAX_WITNESSES:
                continue
            binding = tuple(zip(names, combo, strict=True))
            for x in self.explain(f.body, inner):
                out.append(Failure(x.literal, x.why, binding + x.bindings, x.fact, x.wanted, x.children))
        if witnesses > MAX_WITNESSES and out:
            last = out[-1]
            more = f"{witnesses - MAX_WITNESSES} more object(s) also falsify {formula_text(f, env)}"
            why = f"{last.why}; {more}" if last.why else more
            out[-1] = Failure(last.literal, why, last.bindings, last.fact, last.wanted, last.children)
        return out

    def _instead(self, fact: Fact) -> str:
        """For a false atom, the true atoms of the same predicate that share its first argument."""
        if len(fact) < 2:
            return ""
        index = self.view[3]
        same = [f for f in index.get((fact[0], 1, fact[1]), ()) if len(f) == len(fact)]
        if not same and len(fact) > 2:
            same = [f for f in index.get((fact[0], len(fact) - 1, fact[-1]), ()) if len(f) == len(fact)]
        if not same:
            return ""
        shown = ", ".join(fact_text(f) for f in same[:2])
        return f"{shown} hold{'s' if len(same) == 1 else ''} instead"
