"""Fast ground simplification: static-guarded quantifier instantiation with memoisation.

``ground_simplify`` instantiates every quantifier over all typed objects. Planning domains guard
quantified variables with static predicates (``forall ?d (or (not (above ?d ?x)) ...)``,
``exists ?t (and (part_of ?a ?t) ...)``, ``forall ?n ?m (when (next ?n ?m) ...)``), so only the
objects for which the static guard holds can give a non-trivial instance: the Simplifier joins the
guards against the initial state instead of enumerating every object. Quantified subformulas are
memoised on the values of their free variables, since one subformula (``not (exists (?z) (on ?z
?o))``) recurs in every binding of the other parameters. Results equal ``normalize.ground_simplify``.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator, Mapping
from typing import Protocol

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    And,
    Atom,
    Domain,
    Equals,
    Exists,
    Forall,
    Formula,
    Imply,
    Not,
    Or,
    TypedVar,
)
from gsr.pddl.walk import free_variables, nnf  # the one copy; the grounder imports it from here


class TypedObjects(Protocol):
    """Objects by type: ``objects(types)`` lists them, ``has(obj, types)`` tests membership."""

    def __call__(self, types: tuple[str, ...]) -> list[str]: ...

    def has(self, obj: str, types: tuple[str, ...]) -> bool: ...


class Simplifier:
    """Ground simplification against one problem's objects and static facts."""

    def __init__(self, objects: TypedObjects, fluent: Iterable[str], init: Iterable[Atom]) -> None:
        self.objects = objects
        self.fluent = frozenset(fluent)
        self.init = frozenset(init)
        # Static look-ups by (predicate, args): tuples hash and compare in C, Atoms do not, and a
        # static atom need not be built at all.
        self.init_keys = frozenset((a.predicate, a.args) for a in self.init)
        self.index: dict[str, list[tuple[str, ...]]] = {}
        for predicate, args in sorted(self.init_keys):  # the keys sort in C, as the Atoms by key
            if predicate not in self.fluent:
                self.index.setdefault(predicate, []).append(args)
        # Keyed by id(); the formula is kept in the value so that the id stays valid.
        self._quant: dict[int, tuple[Formula, tuple[str, ...], tuple[Atom, ...]]] = {}
        self._memo: dict[tuple, Formula] = {}
        self._lits: dict[int, tuple[Formula, tuple[tuple[Atom, bool], ...] | None]] = {}

    def literals(self, formula: Formula) -> tuple[tuple[Atom, bool], ...] | None:
        """The literals of a conjunction of literals (cached), or None for any other formula."""
        entry = self._lits.get(id(formula))
        if entry is None:
            out: list[tuple[Atom, bool]] | None = []
            for p in _flatten(formula, And):
                if isinstance(p, Atom):
                    out.append((p, True))
                elif isinstance(p, Not) and isinstance(p.formula, Atom):
                    out.append((p.formula, False))
                else:
                    out = None
                    break
            entry = self._lits[id(formula)] = (formula, tuple(out) if out is not None else None)
        return entry[1]

    def ground_literals(
        self, literals: tuple[tuple[Atom, bool], ...], binding: Mapping[str, str]
    ) -> frozenset[tuple[Atom, bool]] | None:
        """Fast path of __call__ + DNF for a conjunction of literals: its fluent literals, None if false."""
        out = []
        fluent, init = self.fluent, self.init_keys
        for atom, pos in literals:
            args = tuple(map(binding.get, atom.args, atom.args))
            if atom.predicate in fluent:
                out.append((Atom(atom.predicate, args), pos))
            elif ((atom.predicate, args) in init) != pos:
                return None
        conj = frozenset(out)
        if len(out) > 1 and any((a, not p) in conj for a, p in out):  # an atom and its negation
            return None
        return conj

    def ground_literal_keys(
        self, literals: tuple[tuple[Atom, bool], ...], binding: Mapping[str, str]
    ) -> frozenset[tuple[tuple[str, tuple[str, ...]], bool]] | None:
        """``ground_literals`` with each fluent atom as its ``(predicate, args)`` key: no Atom is
        built, and the set hashes its literals in C (effect conditions, gsr.plan.grounding.effects)."""
        out = []
        fluent, init = self.fluent, self.init_keys
        for atom, pos in literals:
            key = (atom.predicate, tuple(map(binding.get, atom.args, atom.args)))
            if atom.predicate in fluent:
                out.append((key, pos))
            elif (key in init) != pos:
                return None
        conj = frozenset(out)
        if len(out) > 1 and any((k, not p) in conj for k, p in out):  # an atom and its negation
            return None
        return conj

    def static(self, atom: Atom) -> bool | None:
        """True/False for a ground static atom, None for a fluent one."""
        if atom.predicate in self.fluent:
            return None
        return atom in self.init

    def guards(self, formula: Formula, positive: bool) -> tuple[Atom, ...]:
        """Static atoms that must hold for a non-trivial instance (conjuncts, or negated disjuncts)."""
        if positive:
            parts = _flatten(formula, And)
            return tuple(p for p in parts if isinstance(p, Atom) and p.predicate not in self.fluent)
        parts = _flatten(formula, Or)
        return tuple(
            p.formula
            for p in parts
            if isinstance(p, Not) and isinstance(p.formula, Atom) and p.formula.predicate not in self.fluent
        )

    def instances(
        self, params: tuple[TypedVar, ...], guards: tuple[Atom, ...], binding: Mapping[str, str]
    ) -> Iterator[dict[str, str]]:
        """Extensions of ``binding`` to ``params`` under which every guard atom is in the initial state."""
        names = {p.name for p in params}
        ptypes = {p.name: p.types for p in params}
        useful = [g for g in guards if names.intersection(g.args)]
        for g in guards:  # a guard without quantified variables is checked once, up front
            if (
                g not in useful
                and (g.predicate, tuple(binding.get(a, a) for a in g.args)) not in self.init_keys
            ):
                return
        index, has, objects = self.index, self.objects.has, self.objects
        # When the guards mention every parameter, a binding that matched the last guard is whole:
        # it is yielded there, without one more generator level per instance.
        last = len(useful) - 1 if all(any(p.name in g.args for g in useful) for p in params) else -1

        def rec(k: int, b: dict[str, str]) -> Iterator[dict[str, str]]:
            if k == len(useful):
                free = [p for p in params if p.name not in b]
                if not free:
                    yield b
                    return
                for combo in itertools.product(*(objects(p.types) for p in free)):
                    full = dict(b)
                    full.update(zip((p.name for p in free), combo, strict=True))
                    yield full
                return
            atom = useful[k]
            for tup in index.get(atom.predicate, ()):
                if len(tup) != len(atom.args):
                    continue
                nb = b
                for a, v in zip(atom.args, tup, strict=True):
                    bound = nb.get(a)
                    if bound is None and a in names:
                        if not has(v, ptypes[a]):
                            break
                        if nb is b:
                            nb = dict(b)
                        nb[a] = v
                    elif (bound if bound is not None else a) != v:
                        break
                else:
                    if k == last:
                        yield nb
                    else:
                        yield from rec(k + 1, nb)

        yield from rec(0, dict(binding))

    def __call__(self, formula: Formula, binding: Mapping[str, str]) -> Formula:
        """Substitute ``binding``, instantiate quantifiers and evaluate equality and static atoms."""
        # Exact-type fast paths for the common nodes (the general isinstance chain below handles the
        # rest, subclasses included); the results are the same objects the chain builds.
        kind = type(formula)
        if kind is Not and type(formula.formula) is Atom:  # type: ignore[union-attr]
            atom = formula.formula  # type: ignore[union-attr]
            args = tuple(map(binding.get, atom.args, atom.args))
            if atom.predicate in self.fluent:
                return Not(Atom(atom.predicate, args))
            return FALSE if (atom.predicate, args) in self.init_keys else TRUE
        if kind is And or kind is Or:
            unit, zero = (TRUE, FALSE) if kind is And else (FALSE, TRUE)
            kept: list[Formula] = []
            for part in formula.parts:  # type: ignore[union-attr]
                g = self(part, binding)
                if g is zero:
                    return zero  # short-circuit: later parts are never simplified
                if g is not unit:
                    kept.append(g)
            if not kept:
                return unit
            if len(kept) == 1:
                return kept[0]
            return kind(tuple(kept))  # type: ignore[operator]
        if kind is Forall or kind is Exists:
            return self._quantifier(formula, binding)  # type: ignore[arg-type]
        if isinstance(formula, Atom):
            args = tuple(map(binding.get, formula.args, formula.args))
            if formula.predicate in self.fluent:
                return Atom(formula.predicate, args)
            return TRUE if (formula.predicate, args) in self.init_keys else FALSE
        if isinstance(formula, Equals):
            left, right = binding.get(formula.left, formula.left), binding.get(formula.right, formula.right)
            if left.startswith("?") or right.startswith("?"):
                raise GSRError(f"free variable in equality ({left} = {right})")
            return TRUE if left == right else FALSE
        if isinstance(formula, Not):
            inner = self(formula.formula, binding)
            if inner is TRUE:
                return FALSE
            if inner is FALSE:
                return TRUE
            return Not(inner)
        if isinstance(formula, (And, Or)):
            return self.combine(isinstance(formula, And), (self(p, binding) for p in formula.parts))
        if isinstance(formula, (Forall, Exists)):
            return self._quantifier(formula, binding)
        if isinstance(formula, Imply):
            return self(nnf(formula), binding)
        raise GSRError(f"unsupported formula in planner: {formula!r}")

    def _quantifier(self, formula: Forall | Exists, binding: Mapping[str, str]) -> Formula:
        entry = self._quant.get(id(formula))
        if entry is None:
            free = tuple(sorted(free_variables(formula)))
            guards = self.guards(formula.body, isinstance(formula, Exists))
            entry = self._quant[id(formula)] = (formula, free, guards)
        _, free, guards = entry
        key = (id(formula), *(binding.get(v, v) for v in free))
        found = self._memo.get(key)
        if found is None:
            conj = isinstance(formula, Forall)
            literal = self._fluent_literal(formula, guards)
            if literal is not None:
                found = self._memo[key] = self._instantiate_literal(formula, literal, binding)
                return found
            parts = (self(formula.body, b) for b in self.instances(formula.params, guards, binding))
            found = self._memo[key] = self.combine(conj, parts)
        return found

    def _fluent_literal(self, formula: Forall | Exists, guards: tuple[Atom, ...]) -> tuple[Atom, bool] | None:
        """(atom, positive) when the body is one fluent literal over one unguarded variable."""
        if guards or len(formula.params) != 1:
            return None
        body = formula.body
        positive = isinstance(body, Atom)
        atom = body if positive else body.formula if isinstance(body, Not) else None
        if not isinstance(atom, Atom) or atom.predicate not in self.fluent:
            return None
        return atom, positive  # type: ignore[return-value]

    def _instantiate_literal(
        self, formula: Forall | Exists, literal: tuple[Atom, bool], binding: Mapping[str, str]
    ) -> Formula:
        """``forall ?z (not (on ?z ?o))`` and the like: one literal per object, in object order.

        Equals the general path (fluent literals never fold to TRUE or FALSE) without a binding
        dict and a recursive simplification per object.
        """
        atom, positive = literal
        var = formula.params[0]
        args = [None if a == var.name else binding.get(a, a) for a in atom.args]
        slots = [k for k, a in enumerate(args) if a is None]
        parts: list[Formula] = []
        for obj in self.objects(var.types):
            for k in slots:
                args[k] = obj
            ground = Atom(atom.predicate, tuple(args))  # type: ignore[arg-type]
            parts.append(ground if positive else Not(ground))
        return self.combine(isinstance(formula, Forall), parts)

    @staticmethod
    def combine(conj: bool, parts: Iterable[Formula]) -> Formula:
        """Conjunction (``conj``) or disjunction of simplified parts, with TRUE/FALSE folded."""
        unit, zero = (TRUE, FALSE) if conj else (FALSE, TRUE)
        kept: list[Formula] = []
        for p in parts:
            if p is zero:
                return zero  # short-circuit: later parts are never simplified
            if p is not unit:
                kept.append(p)
        if not kept:
            return unit
        if len(kept) == 1:
            return kept[0]
        return And(tuple(kept)) if conj else Or(tuple(kept))


def _flatten(formula: Formula, kind: type) -> list[Formula]:
    if isinstance(formula, kind):
        out: list[Formula] = []
        for p in formula.parts:
            out.extend(_flatten(p, kind))
        return out
    return [formula]


class ObjectsByType:
    """Objects of a type (either-tuples allowed), cached and sorted for determinism."""

    def __init__(self, domain: Domain, objects: dict[str, str]) -> None:
        self.domain, self.objects = domain, objects
        self.cache: dict[tuple[str, ...], list[str]] = {}
        self.sets: dict[tuple[str, ...], frozenset[str]] = {}
        # The objects by their declared type: a query tests each distinct type once, not each object.
        self._by_type: dict[str, list[str]] = {}
        for o, t in objects.items():
            self._by_type.setdefault(t, []).append(o)

    def __call__(self, types: tuple[str, ...]) -> list[str]:
        found = self.cache.get(types)
        if found is None:
            is_subtype = self.domain.is_subtype
            found = sorted(o for t, os in self._by_type.items() if is_subtype(t, types) for o in os)
            self.cache[types] = found
            self.sets[types] = frozenset(found)
        return found

    def has(self, obj: str, types: tuple[str, ...]) -> bool:
        """True when ``obj`` is of one of ``types``."""
        if types not in self.sets:
            self(types)
        return obj in self.sets[types]
