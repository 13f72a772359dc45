"""ADL normalisation: flattened conditional effects, equality cases and ground simplification.

The normal forms themselves (NNF, DNF) are the formula walker's (gsr.pddl.walk.nnf / to_dnf). The
planner compiles, it does not reject: ``imply`` and ``not`` are pushed inward (NNF), existential
preconditions at the top level become extra action parameters, universal quantifiers are
instantiated over the finite typed objects, equality and static predicates are evaluated at
grounding time, and what is left of a ground precondition is put into disjunctive normal form
(each disjunct becomes one ground operator variant). Effects are flattened into
``(forall-vars, condition, literal)`` triples.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    Action,
    And,
    AndEffect,
    Atom,
    Effect,
    Equals,
    Exists,
    Forall,
    ForallEffect,
    Formula,
    Imply,
    Increase,
    Literal,
    Not,
    Or,
    TypedVar,
    When,
    is_variable,
)
from gsr.pddl.walk import nnf


@dataclass(frozen=True, slots=True)
class SchemaEffect:
    """One flattened effect literal with the universally quantified variables and condition above it."""

    params: tuple[TypedVar, ...]
    condition: Formula
    literal: Literal


@dataclass(frozen=True, slots=True)
class Schema:
    """A normalised action schema: join atoms for grounding plus a residual NNF precondition."""

    name: str
    params: tuple[TypedVar, ...]
    extra: tuple[TypedVar, ...]
    join: tuple[Atom, ...]
    residual: Formula
    effects: tuple[SchemaEffect, ...]
    costs: tuple[Increase, ...]

    @property
    def all_params(self) -> tuple[TypedVar, ...]:
        """Action parameters followed by the lifted existential variables."""
        return self.params + self.extra


class _Fresh:
    """Deterministic fresh variable names (``?x#1``) so that lifted variables never clash."""

    def __init__(self) -> None:
        self.count = 0

    def __call__(self, var: str) -> str:
        self.count += 1
        return f"{var}#{self.count}"


def rename(formula: Formula, mapping: Mapping[str, str]) -> Formula:
    """Substitute variables (or objects) in a formula; quantified variables shadow the mapping."""
    if not mapping:
        return formula
    if isinstance(formula, Atom):
        return Atom(formula.predicate, tuple(mapping.get(a, a) for a in formula.args))
    if isinstance(formula, Equals):
        return Equals(mapping.get(formula.left, formula.left), mapping.get(formula.right, formula.right))
    if isinstance(formula, Not):
        return Not(rename(formula.formula, mapping))
    if isinstance(formula, (And, Or)):
        return type(formula)(tuple(rename(p, mapping) for p in formula.parts))
    if isinstance(formula, Imply):
        return Imply(rename(formula.condition, mapping), rename(formula.then, mapping))
    if isinstance(formula, (Exists, Forall)):
        inner = {k: v for k, v in mapping.items() if k not in {p.name for p in formula.params}}
        return type(formula)(formula.params, rename(formula.body, inner))
    raise GSRError(f"unsupported formula in planner: {formula!r}")


def _flatten_and(formula: Formula) -> list[Formula]:
    if isinstance(formula, And):
        out: list[Formula] = []
        for part in formula.parts:
            out.extend(_flatten_and(part))
        return out
    return [formula]


def _flatten_effect(
    effect: Effect,
    params: tuple[TypedVar, ...],
    condition: list[Formula],
    fresh: _Fresh,
    out: list[SchemaEffect],
    costs: list[Increase],
) -> None:
    if isinstance(effect, Literal):
        cond = nnf(And(tuple(condition))) if condition else TRUE
        out.append(SchemaEffect(params, cond, effect))
    elif isinstance(effect, AndEffect):
        for part in effect.parts:
            _flatten_effect(part, params, condition, fresh, out, costs)
    elif isinstance(effect, When):
        _flatten_effect(effect.effect, params, [*condition, effect.condition], fresh, out, costs)
    elif isinstance(effect, ForallEffect):
        # Rename the quantified variables so nested quantifiers never shadow action parameters.
        mapping = {v.name: fresh(v.name) for v in effect.params}
        new_params = tuple(TypedVar(mapping[v.name], v.types) for v in effect.params)
        _flatten_effect(
            _rename_effect(effect.effect, mapping), params + new_params, condition, fresh, out, costs
        )
    elif isinstance(effect, Increase):
        costs.append(effect)
    else:
        raise GSRError(f"unsupported effect in planner: {effect!r}")


def _rename_effect(effect: Effect, mapping: Mapping[str, str]) -> Effect:
    if isinstance(effect, Literal):
        return Literal(rename(effect.atom, mapping), effect.negated)  # type: ignore[arg-type]
    if isinstance(effect, AndEffect):
        return AndEffect(tuple(_rename_effect(p, mapping) for p in effect.parts))
    if isinstance(effect, When):
        return When(rename(effect.condition, mapping), _rename_effect(effect.effect, mapping))
    if isinstance(effect, ForallEffect):
        inner = {k: v for k, v in mapping.items() if k not in {p.name for p in effect.params}}
        return ForallEffect(effect.params, _rename_effect(effect.effect, inner))
    if isinstance(effect, Increase):
        return Increase(effect.function, tuple(mapping.get(a, a) for a in effect.args), effect.amount)
    raise GSRError(f"unsupported effect in planner: {effect!r}")


def normalize_action(action: Action) -> Schema:
    """Normalise one action schema: NNF precondition, lifted top-level existentials, flat effects."""
    fresh = _Fresh()
    join: list[Atom] = []
    extra: list[TypedVar] = []
    residual: list[Formula] = []
    todo = _flatten_and(nnf(action.precondition))
    while todo:
        part = todo.pop(0)
        if isinstance(part, Atom):
            join.append(part)
        elif isinstance(part, Exists):
            # A top-level existential is just more parameters to choose (FD does the same).
            mapping = {v.name: fresh(v.name) for v in part.params}
            extra.extend(TypedVar(mapping[v.name], v.types) for v in part.params)
            todo.extend(_flatten_and(rename(part.body, mapping)))
        else:
            residual.append(part)
    effects: list[SchemaEffect] = []
    costs: list[Increase] = []
    _flatten_effect(action.effect, (), [], fresh, effects, costs)
    return Schema(
        name=action.name,
        params=action.params,
        extra=tuple(extra),
        join=tuple(join),
        residual=And(tuple(residual)) if residual else TRUE,
        effects=tuple(effects),
        costs=tuple(costs),
    )


EQUALS = "="  # the join's name for equality: grounding indexes one (o, o) tuple per object


def split_cases(schema: Schema) -> list[Schema]:
    """A schema whose precondition is a case analysis, a top-level ``(or (and (= ?d up) ... (inc
    ?y ?y2)) (and (= ?d down) ...) ...)``, becomes one schema per case (FD's translator splits every
    disjunction the same way), so each case's atoms and equalities join like the schema's own.

    The equalities become join atoms of the virtual predicate ``=`` (variables bound together, a
    variable bound to a constant), and so do the equalities at the top level of the precondition.
    On IPC folding's second pass (seven parameters over 23
    coordinates) this lists a few thousand bindings instead of millions. Only disjunctions in
    which every case is a conjunction holding an equality are split: other disjunctions (pick's
    ``(or (on ?o ?from) (in ?o ?from))``) keep their own join (see gsr.plan.grounding.fixpoint).
    """
    parts = _flatten_and(schema.residual)
    if any(isinstance(q, Equals) for q in parts):
        # Top-level equalities (labyrinth's (= ?yfrom ?yto), (= ?dfrom w)) join the same way.
        join = (*schema.join, *(Atom(EQUALS, (q.left, q.right)) for q in parts if isinstance(q, Equals)))
        rest = [q for q in parts if not isinstance(q, Equals)]
        residual = And(tuple(rest)) if rest else TRUE
        schema = Schema(
            schema.name, schema.params, schema.extra, join, residual, schema.effects, schema.costs
        )
        parts = rest
    for k, part in enumerate(parts):
        if not isinstance(part, Or) or not part.parts:
            continue
        cases = [_flatten_and(case) for case in part.parts]
        if not all(any(isinstance(q, Equals) for q in case) for case in cases):
            continue
        rest = parts[:k] + parts[k + 1 :]
        out = []
        for case in cases:
            join = list(schema.join)
            residual = list(rest)
            for q in case:
                if isinstance(q, Atom):
                    join.append(q)
                elif isinstance(q, Equals):
                    join.append(Atom(EQUALS, (q.left, q.right)))
                else:
                    residual.append(q)
            out.extend(
                split_cases(
                    Schema(
                        schema.name,
                        schema.params,
                        schema.extra,
                        tuple(join),
                        And(tuple(residual)) if residual else TRUE,
                        schema.effects,
                        schema.costs,
                    )
                )
            )
        return out
    return [schema]


# ------------------------------------------------------------------ ground simplification


Objects = Callable[[tuple[str, ...]], list[str]]
Static = Callable[[Atom], bool | None]  # True / False for static atoms, None for fluent ones


def ground_simplify(
    formula: Formula, binding: Mapping[str, str], objects: Objects, static: Static
) -> Formula:
    """Substitute, instantiate quantifiers over typed objects and evaluate equality and static atoms."""
    if isinstance(formula, Atom):
        atom = Atom(formula.predicate, tuple(binding.get(a, a) for a in formula.args))
        value = static(atom)
        if value is None:
            return atom
        return TRUE if value else FALSE
    if isinstance(formula, Equals):
        left, right = binding.get(formula.left, formula.left), binding.get(formula.right, formula.right)
        if is_variable(left) or is_variable(right):
            raise GSRError(f"free variable in equality ({left} = {right})")
        return TRUE if left == right else FALSE
    if isinstance(formula, Not):
        inner = ground_simplify(formula.formula, binding, objects, static)
        if inner == TRUE:
            return FALSE
        if inner == FALSE:
            return TRUE
        return Not(inner)
    if isinstance(formula, (And, Forall, Or, Exists)):
        conj = isinstance(formula, (And, Forall))
        if isinstance(formula, (Forall, Exists)):
            parts = []
            domains = [objects(v.types) for v in formula.params]
            for combo in itertools.product(*domains):
                inner = dict(binding)
                inner.update(zip((v.name for v in formula.params), combo, strict=True))
                parts.append(ground_simplify(formula.body, inner, objects, static))
        else:
            parts = [ground_simplify(p, binding, objects, static) for p in formula.parts]
        unit, zero = (TRUE, FALSE) if conj else (FALSE, TRUE)
        kept: list[Formula] = []
        for p in parts:
            if p == zero:
                return zero
            if p != unit:
                kept.append(p)
        if not kept:
            return unit
        if len(kept) == 1:
            return kept[0]
        return And(tuple(kept)) if conj else Or(tuple(kept))
    if isinstance(formula, Imply):
        return ground_simplify(nnf(formula), binding, objects, static)
    raise GSRError(f"unsupported formula in planner: {formula!r}")
