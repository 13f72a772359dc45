"""One traversal of PDDL formulas and effects: children, fold, map, and what is built on them.

Every formula class of :mod:`gsr.pddl.model` is known here once: :func:`children` lists a node's
sub-formulas, :func:`bound_variables` the variables a quantifier binds, :func:`with_children` rebuilds
a node over new sub-formulas. On those rest the generic walks (:func:`subformulas`, :func:`fold`,
:func:`map_formula`, :func:`map_atoms`) and the operations several modules share:
:func:`free_variables` (the only copy: the checker, the planner's simplifier and the goal reader use
it), :func:`conjuncts`, :func:`negate` (negation pushed inwards, as the checker's code generator and
quantifier joins need it), the normal forms :func:`nnf` and :func:`to_dnf` (the planner's grounding
and the grounder's goal comparison use them), and for effects :func:`effect_leaves` /
:func:`effect_literals`.

Modules whose job *is* a per-node dispatch (the writer, the checker's code generator, the diagnosis
explainer, the planner's ground simplifier) keep their own ``isinstance`` chains: there the chain is
the content, not boilerplate.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TypeVar

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    And,
    AndEffect,
    Atom,
    Effect,
    Equals,
    Exists,
    Forall,
    ForallEffect,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Increase,
    Literal,
    Not,
    Or,
    TypedVar,
    When,
    is_variable,
)

T = TypeVar("T")

#: Formula classes that bind variables.
QUANTIFIERS = (Exists, Forall, ForN, ForPairs)


def children(f: Formula) -> tuple[Formula, ...]:
    """The direct sub-formulas of ``f`` (none for atoms and equalities)."""
    if isinstance(f, (And, Or)):
        return f.parts
    if isinstance(f, Not):
        return (f.formula,)
    if isinstance(f, Imply):
        return (f.condition, f.then)
    if isinstance(f, QUANTIFIERS):
        return (f.body,)
    return ()


def bound_variables(f: Formula) -> tuple[TypedVar, ...]:
    """The variables ``f`` itself binds: a quantifier's parameters (both lists of ``forpairs``), else ()."""
    if isinstance(f, ForPairs):
        return (*f.first, *f.second)
    if isinstance(f, (Exists, Forall, ForN)):
        return f.params
    return ()


def with_children(f: Formula, parts: tuple[Formula, ...]) -> Formula:
    """``f`` rebuilt over ``parts`` (as many as :func:`children` gave); ``f`` itself when unchanged."""
    if parts == children(f):
        return f
    if isinstance(f, And):
        return And(parts)
    if isinstance(f, Or):
        return Or(parts)
    if isinstance(f, Not):
        return Not(parts[0])
    if isinstance(f, Imply):
        return Imply(parts[0], parts[1])
    if isinstance(f, Exists):
        return Exists(f.params, parts[0])
    if isinstance(f, Forall):
        return Forall(f.params, parts[0])
    if isinstance(f, ForN):
        return ForN(f.count, f.params, parts[0])
    if isinstance(f, ForPairs):
        return ForPairs(f.first, f.second, parts[0])
    raise TypeError(f"{type(f).__name__} has no sub-formulas to replace")


def subformulas(f: Formula) -> Iterator[Formula]:
    """``f`` and every formula inside it, parents before children, left to right."""
    stack = [f]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(reversed(children(node)))


def fold(f: Formula, combine: Callable[[Formula, tuple[T, ...]], T]) -> T:
    """Bottom-up fold: ``combine(node, results of its children)`` for every node, the root's result returned."""
    return combine(f, tuple(fold(c, combine) for c in children(f)))


def map_formula(f: Formula, fn: Callable[[Formula], Formula]) -> Formula:
    """Rebuild ``f`` bottom-up, applying ``fn`` to every node after its children were mapped."""
    return fn(with_children(f, tuple(map_formula(c, fn) for c in children(f))))


def map_atoms(f: Formula, fn: Callable[[Atom], Formula]) -> Formula:
    """``f`` with every atom replaced by ``fn(atom)`` (structure, quantifiers and equalities kept)."""
    return map_formula(f, lambda node: fn(node) if isinstance(node, Atom) else node)


def atoms(f: Formula) -> Iterator[Atom]:
    """Every atom in ``f``, left to right (repeats included)."""
    return (node for node in subformulas(f) if isinstance(node, Atom))


def terms(f: Formula) -> tuple[str, ...]:
    """The object names and variables ``f`` itself mentions (an atom's arguments, an equality's sides)."""
    if isinstance(f, Atom):
        return f.args
    if isinstance(f, Equals):
        return (f.left, f.right)
    return ()


def _free(node: Formula, inner: tuple[frozenset[str], ...]) -> frozenset[str]:
    own = frozenset(t for t in terms(node) if is_variable(t)).union(*inner)
    bound = bound_variables(node)
    return own - {p.name for p in bound} if bound else own


def free_variables(f: Formula) -> frozenset[str]:
    """Variables of ``f`` not bound by one of its quantifiers (``forn`` and ``forpairs`` included)."""
    return fold(f, _free)


def conjuncts(f: Formula) -> tuple[Formula, ...]:
    """Top-level conjuncts of a formula (flattening nested ``and``)."""
    if isinstance(f, And):
        return tuple(c for part in f.parts for c in conjuncts(part))
    return (f,)


def negate(f: Formula) -> Formula:
    """``(not f)`` with the negation pushed inwards through and/or/imply/exists/forall, down to literals
    (``forn``/``forpairs`` keep an outer ``not``; a double negation cancels)."""
    if isinstance(f, Not):
        return f.formula
    if isinstance(f, And):
        return Or(tuple(negate(p) for p in f.parts))
    if isinstance(f, Or):
        return And(tuple(negate(p) for p in f.parts))
    if isinstance(f, Imply):
        return And((f.condition, negate(f.then)))
    if isinstance(f, Exists):
        return Forall(f.params, negate(f.body))
    if isinstance(f, Forall):
        return Exists(f.params, negate(f.body))
    return Not(f)


def nnf(f: Formula, negated: bool = False) -> Formula:
    """Negation normal form of ``f`` (of ``(not f)`` when ``negated``): ``imply`` eliminated, ``not``
    only directly above atoms, equalities and the counting quantifiers ``forn``/``forpairs``, which
    are kept whole (no ``not`` passes through a count); the planner refuses those when it grounds."""
    if isinstance(f, (Atom, Equals, ForN, ForPairs)):
        return Not(f) if negated else f
    if isinstance(f, Not):
        return nnf(f.formula, not negated)
    if isinstance(f, And):
        parts = tuple(nnf(p, negated) for p in f.parts)
        return Or(parts) if negated else And(parts)
    if isinstance(f, Or):
        parts = tuple(nnf(p, negated) for p in f.parts)
        return And(parts) if negated else Or(parts)
    if isinstance(f, Imply):
        return nnf(Or((Not(f.condition), f.then)), negated)
    if isinstance(f, Exists):
        body = nnf(f.body, negated)
        return Forall(f.params, body) if negated else Exists(f.params, body)
    if isinstance(f, Forall):
        body = nnf(f.body, negated)
        return Exists(f.params, body) if negated else Forall(f.params, body)
    raise GSRError(f"not a formula: {f!r}")


#: A ground literal: (atom, positive). A DNF is a list of conjunctions of such literals.
GroundLiteral = tuple[Atom, bool]
Conjunction = frozenset[GroundLiteral]
#: Beyond this many disjuncts a formula is too disjunctive to compile (the planner's precondition limit).
DNF_LIMIT = 512


def to_dnf(f: Formula, limit: int = DNF_LIMIT) -> list[Conjunction]:
    """Disjunctive normal form of a ground NNF formula whose equalities and quantifiers are decided
    (``TRUE``/``FALSE``, atoms, negated atoms, and/or): a list of conjunctions, contradictory ones
    dropped, each once; more than ``limit`` disjuncts raise ``GSRError``."""
    if f == TRUE:
        return [frozenset()]
    if f == FALSE:
        return []
    if isinstance(f, Atom):
        return [frozenset({(f, True)})]
    if isinstance(f, Not) and isinstance(f.formula, Atom):
        return [frozenset({(f.formula, False)})]
    if isinstance(f, Or):
        out: list[Conjunction] = []
        seen: set[Conjunction] = set()
        for part in f.parts:
            for conj in to_dnf(part, limit):
                if conj not in seen:
                    seen.add(conj)
                    out.append(conj)
        if len(out) > limit:
            raise GSRError(f"formula too disjunctive to compile (> {limit} disjuncts)")
        return out
    if isinstance(f, And):
        acc: list[Conjunction] = [frozenset()]
        for part in f.parts:
            nxt: list[Conjunction] = []
            seen = set()
            for left in acc:
                for right in to_dnf(part, limit):
                    merged = left | right
                    if merged in seen or any((a, not p) in merged for a, p in right):
                        continue
                    seen.add(merged)
                    nxt.append(merged)
            if len(nxt) > limit:
                raise GSRError(f"formula too disjunctive to compile (> {limit} disjuncts)")
            acc = nxt
        return acc
    raise GSRError(f"formula not in ground NNF: {f!r}")


# ----------------------------------------------------------------- effects


def effect_leaves(e: Effect) -> Iterator[Literal | Increase]:
    """Every literal and cost increase of an effect, including those under ``when`` and ``forall``."""
    if isinstance(e, (Literal, Increase)):
        yield e
    elif isinstance(e, AndEffect):
        for part in e.parts:
            yield from effect_leaves(part)
    elif isinstance(e, (When, ForallEffect)):
        yield from effect_leaves(e.effect)


def effect_literals(e: Effect) -> Iterator[Literal]:
    """Every add/delete literal of an effect, including those under ``when`` and ``forall``."""
    return (leaf for leaf in effect_leaves(e) if isinstance(leaf, Literal))
