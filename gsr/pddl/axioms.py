"""Derived predicates (PDDL axioms): stratification and their value in one state.

A derived atom holds in a state when it is in the *stratified least fixpoint* of the domain's
rules over that state: the derived predicates are split into strata so that a rule only uses
derived predicates of its own stratum positively and of lower strata (already final) negatively;
each stratum is then the least fixpoint of its rules. This module evaluates the rules lifted, for
one state at a time (the validator's use: only the states a plan visits are looked at); the
planner grounds the rules instead (gsr.plan.task.Task.close).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping

from gsr.errors import GSRError
from gsr.pddl.model import And as _And
from gsr.pddl.model import (
    Atom,
    Axiom,
    Domain,
    Equals,
    Exists,
    Forall,
    Formula,
    Imply,
    Not,
    is_variable,
)
from gsr.pddl.model import Or as _Or


def _derived_uses(formula: Formula, derived: frozenset[str], positive: bool, out: set) -> None:
    """Collect (predicate, occurs positively) for the derived atoms of a formula."""
    if isinstance(formula, Atom):
        if formula.predicate in derived:
            out.add((formula.predicate, positive))
    elif isinstance(formula, Not):
        _derived_uses(formula.formula, derived, not positive, out)
    elif isinstance(formula, (_And, _Or)):
        for p in formula.parts:
            _derived_uses(p, derived, positive, out)
    elif isinstance(formula, Imply):
        _derived_uses(formula.condition, derived, not positive, out)
        _derived_uses(formula.then, derived, positive, out)
    elif isinstance(formula, (Exists, Forall)):
        _derived_uses(formula.body, derived, positive, out)


def strata(domain: Domain) -> list[list[str]]:
    """The derived predicates by stratum, lowest first; a GSRError when they are not stratifiable
    (a predicate that depends negatively on itself, directly or through others)."""
    derived = domain.derived
    if not derived:
        return []
    uses = {}
    for ax in domain.axioms:
        found: set[tuple[str, bool]] = set()
        _derived_uses(ax.body, derived, True, found)
        uses.setdefault(ax.name, set()).update(found)
    level = dict.fromkeys(sorted(derived), 0)
    limit = len(derived)
    changed = True
    while changed:
        changed = False
        for head, used in uses.items():
            for pred, positive in used:
                need = level[pred] + (0 if positive else 1)
                if level[head] < need:
                    if need > limit:
                        raise GSRError(
                            f"derived predicate {head!r} depends negatively on itself (not stratifiable)"
                        )
                    level[head] = need
                    changed = True
    out: list[list[str]] = [[] for _ in range(max(level.values()) + 1)]
    for pred, k in level.items():
        out[k].append(pred)
    return [s for s in out if s]


def _conjuncts(f: Formula) -> list[Formula]:
    if isinstance(f, _And):
        return [q for p in f.parts for q in _conjuncts(p)]
    return [f]


class _Evaluator:
    """Lifted evaluation of axiom bodies over one set of true atoms."""

    def __init__(self, domain: Domain, objects: Mapping[str, str], atoms: set[Atom]) -> None:
        self.domain = domain
        self.objects = objects
        self.atoms = atoms
        self.by_pred: dict[str, list[tuple[str, ...]]] = {}
        # (predicate, argument position, value) -> the true atoms' argument tuples: a join atom
        # with a bound argument scans only its bucket (PSR-style closures: the lines into ?n).
        self.by_arg: dict[tuple[str, int, str], list[tuple[str, ...]]] = {}
        for a in atoms:
            self._index(a)
        self._typed: dict[tuple[str, ...], tuple[str, ...]] = {}

    def _index(self, atom: Atom) -> None:
        self.by_pred.setdefault(atom.predicate, []).append(atom.args)
        for k, v in enumerate(atom.args):
            self.by_arg.setdefault((atom.predicate, k, v), []).append(atom.args)

    def add(self, atom: Atom) -> None:
        self.atoms.add(atom)
        self._index(atom)

    def _candidates(self, atom: Atom, b: Mapping[str, str]) -> list[tuple[str, ...]]:
        """The true tuples a join atom can match under ``b``: its smallest bound-argument bucket."""
        best = self.by_pred.get(atom.predicate, [])
        for k, term in enumerate(atom.args):
            v = b.get(term) if is_variable(term) else term
            if v is not None:
                found = self.by_arg.get((atom.predicate, k, v), [])
                if len(found) < len(best):
                    best = found
        return best

    def typed(self, types: tuple[str, ...]) -> tuple[str, ...]:
        hit = self._typed.get(types)
        if hit is None:
            hit = self._typed[types] = tuple(
                o for o, t in self.objects.items() if self.domain.is_subtype(t, types)
            )
        return hit

    def holds(self, f: Formula, b: Mapping[str, str]) -> bool:
        """Truth of a formula whose free variables are all bound in ``b``."""
        if isinstance(f, Atom):
            return Atom(f.predicate, tuple(b.get(a, a) for a in f.args)) in self.atoms
        if isinstance(f, Equals):
            return b.get(f.left, f.left) == b.get(f.right, f.right)
        if isinstance(f, Not):
            return not self.holds(f.formula, b)
        if isinstance(f, _And):
            return all(self.holds(p, b) for p in f.parts)
        if isinstance(f, _Or):
            return any(self.holds(p, b) for p in f.parts)
        if isinstance(f, Imply):
            return not self.holds(f.condition, b) or self.holds(f.then, b)
        if isinstance(f, Exists):
            shadowed = {p.name for p in f.params}  # an inner (exists (?q) ...) rebinds ?q
            inner = {k: v for k, v in b.items() if k not in shadowed}
            return next(self.solutions(f.body, inner, f.params), None) is not None
        if isinstance(f, Forall):
            names = [p.name for p in f.params]
            for combo in itertools.product(*(self.typed(p.types) for p in f.params)):
                if not self.holds(f.body, {**b, **dict(zip(names, combo, strict=True))}):
                    return False
            return True
        raise GSRError(f"unsupported formula in a derived predicate: {f!r}")

    def solutions(self, f: Formula, b: dict[str, str], free: tuple) -> Iterator[dict[str, str]]:
        """Bindings of the typed variables ``free`` (extending ``b``) under which ``f`` holds.

        Positive atoms of a conjunction are joined against the true atoms first, so a rule such
        as ``(and (edge ?x ?z) (path ?z ?y))`` never enumerates every object for ``?z``.
        """
        # Existentials among the conjuncts, nested at any depth (``(exists (?q) (exists (?m)
        # (and ...)))``), become more variables to join; one whose variable names are already in
        # use (shadowing) stays a test.
        parts = _conjuncts(f)
        names = set(b) | {p.name for p in free}
        while True:
            flat: list[Formula] = []
            for p in parts:
                if isinstance(p, Exists) and not names & {q.name for q in p.params}:
                    free = (*free, *p.params)
                    names.update(q.name for q in p.params)
                    flat.extend(_conjuncts(p.body))
                else:
                    flat.append(p)
            if len(flat) == len(parts) and all(x is y for x, y in zip(flat, parts, strict=True)):
                break
            parts = flat
        allowed = {p.name: p.types for p in free}
        joins = tuple(p for p in parts if isinstance(p, Atom))
        rest = [p for p in parts if not isinstance(p, Atom)]
        yield from self._join(joins, b, allowed, rest)

    def _join(self, joins: tuple[Atom, ...], b, allowed, rest) -> Iterator[dict[str, str]]:
        if not joins:
            unbound = [v for v in allowed if v not in b]
            for combo in itertools.product(*(self.typed(allowed[v]) for v in unbound)):
                full = {**b, **dict(zip(unbound, combo, strict=True))}
                if all(self.holds(p, full) for p in rest):
                    yield full
            return
        # Join ordering: the atom with the fewest candidate tuples under ``b`` goes next.
        k, tuples = 0, None
        for i, a in enumerate(joins):
            found = self._candidates(a, b)
            if tuples is None or len(found) < len(tuples):
                k, tuples = i, found
        atom, others = joins[k], joins[:k] + joins[k + 1 :]
        for args in tuples:
            if len(args) != len(atom.args):
                continue
            nb = dict(b)
            for term, value in zip(atom.args, args, strict=True):
                if is_variable(term):
                    bound = nb.get(term)
                    if bound is None:
                        types = allowed.get(term)
                        if types is None or value not in self.objects:
                            break
                        if not self.domain.is_subtype(self.objects[value], types):
                            break
                        nb[term] = value
                    elif bound != value:
                        break
                elif term != value:
                    break
            else:
                yield from self._join(others, nb, allowed, rest)


def derive(domain: Domain, objects: Mapping[str, str], atoms: frozenset[Atom] | set[Atom]) -> frozenset[Atom]:
    """The atoms with derived atoms recomputed: the basic atoms of ``atoms`` plus the stratified
    least fixpoint of the domain's rules over them (derived atoms in ``atoms`` are ignored)."""
    if not domain.axioms:
        return frozenset(atoms)
    derived = domain.derived
    ev = _Evaluator(domain, objects, {a for a in atoms if a.predicate not in derived})
    by_head: dict[str, list[Axiom]] = {}
    for ax in domain.axioms:
        by_head.setdefault(ax.name, []).append(ax)
    for stratum in strata(domain):
        rules = [ax for pred in stratum for ax in by_head[pred]]
        changed = True
        while changed:  # naive fixpoint: rounds as deep as the recursion
            changed = False
            for ax in rules:
                names = tuple(p.name for p in ax.params)
                for b in list(ev.solutions(ax.body, {}, ax.params)):
                    head = Atom(ax.name, tuple(b[n] for n in names))
                    if head not in ev.atoms:
                        ev.add(head)
                        changed = True
    return frozenset(ev.atoms)
