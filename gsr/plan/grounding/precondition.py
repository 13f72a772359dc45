"""Ground preconditions after simplification: their delete-relaxed core and their DNF.

A fired action's simplified precondition is mostly shared structure: the quantifier instances and
the conjuncts over fewer variables than the action are memoised objects (``(not (exists ?z (on ?z
?o)))`` is one ``And`` of negated atoms for every pick of ``?o``). Both the relaxed core and the DNF
parts are therefore cached per formula object (by id; the cache keeps the object alive).
"""

from __future__ import annotations

from operator import invert

from gsr.pddl.model import FALSE, TRUE, And, Atom, Formula, Not, Or
from gsr.pddl.walk import DNF_LIMIT, Conjunction, to_dnf
from gsr.plan.grounding.simplify import Simplifier

FormulaCache = dict[object, tuple[Formula, object]]
AtomKey = tuple[str, tuple[str, ...]]  # (predicate, args): hashed and compared in C


def relaxed_core(formula: Formula, cache: FormulaCache) -> Formula:
    """What the delete relaxation tests of a ground NNF formula: negative literals dropped (true).

    The result is TRUE, an atom, or an And/Or over such; ``relaxed(relaxed_core(f), r)`` equals
    ``relaxed(f, r)`` for every reached set ``r``.
    """
    if isinstance(formula, Atom):
        return formula
    if not isinstance(formula, (And, Or)):
        return TRUE  # a negative literal (or TRUE)
    hit = cache.get(id(formula))
    if hit is not None:
        return hit[1]  # type: ignore[return-value]
    conj = isinstance(formula, And)
    kept: list[Formula] = []
    out: Formula | None = None
    for p in formula.parts:
        q = relaxed_core(p, cache)
        if q is TRUE:
            if not conj:
                out = TRUE  # a disjunction with a negative literal always holds relaxed
                break
            continue
        kept.append(q)
    if out is None:
        # An empty disjunction (FALSE) stays false; an empty conjunction is TRUE.
        out = (
            (TRUE if conj else FALSE)
            if not kept
            else kept[0]
            if len(kept) == 1
            else (And if conj else Or)(tuple(kept))
        )
    cache[id(formula)] = (formula, out)
    return out


def relaxed(formula: Formula, reached: set[AtomKey]) -> bool:
    """Whether a ground NNF formula can hold in the delete relaxation (negative literals ignored).

    ``reached`` holds (predicate, args) keys: tuples hash and compare in C, Atoms do not.
    """
    if isinstance(formula, Atom):
        return (formula.predicate, formula.args) in reached
    if isinstance(formula, And):
        return all(relaxed(p, reached) for p in formula.parts)
    if isinstance(formula, Or):
        return any(relaxed(p, reached) for p in formula.parts)
    return True  # a negative literal


def prune(formula: Formula, reached: set[Atom]) -> Formula:
    """Unreachable atoms are false: simplify a ground NNF formula before its DNF is taken."""
    if isinstance(formula, Atom):
        return formula if formula in reached else FALSE
    if isinstance(formula, Not):
        return formula if formula.formula in reached else TRUE
    if isinstance(formula, (And, Or)):
        return Simplifier.combine(isinstance(formula, And), (prune(p, reached) for p in formula.parts))
    return formula


def _alternative(formula: Formula, ids: dict[AtomKey, int]) -> list[int] | None:
    """The literals of a literal or conjunction of literals, unreached atoms pruned; None if false."""
    out: list[int] = []
    stack = [formula]
    while stack:
        p = stack.pop()
        if isinstance(p, And):
            stack.extend(p.parts)
        elif isinstance(p, Atom):
            i = ids.get((p.predicate, p.args))
            if i is None:
                return None
            out.append(i)
        elif isinstance(p, Not) and isinstance(p.formula, Atom):
            i = ids.get((p.formula.predicate, p.formula.args))
            if i is not None:
                out.append(~i)
        else:
            raise TypeError  # not a conjunction of literals: the general path handles it
    return out


# Literals over atom ids: ``i`` for atom i, ``~i`` (negative) for its negation. A conjunct's
# contribution to the DNF: (its literals, its disjunctions of alternatives); False when it cannot
# hold, None when it has a shape only the general path handles.
IdConjunction = frozenset[int]
Scanned = tuple[list[int], list[list[IdConjunction]]] | bool | None


def _scan(formula: Formula, ids: dict[AtomKey, int], cache: FormulaCache) -> Scanned:
    """Literals and disjunctions of one conjunct of a precondition (unreached atoms pruned).

    A compound alternative is converted once per object (``cache``, keyed ``(id, "alt")``): the
    instantiated quantifiers inside ``(imply (in ?o ?from) (not (exists ...)))`` are shared by
    every binding with that ``?from`` while the disjunction around them is new each time.
    """
    literals: list[int] = []
    choices: list[list[IdConjunction]] = []
    stack = [formula]
    try:
        while stack:
            p = stack.pop()
            if isinstance(p, And):
                stack.extend(p.parts)
            elif isinstance(p, Or):
                alts: list[IdConjunction] | None = []
                for q in p.parts:
                    if isinstance(q, Atom):  # the common alternative, inline
                        i = ids.get((q.predicate, q.args))
                        if i is not None:
                            alts.append(frozenset((i,)))  # type: ignore[union-attr]
                        continue
                    if type(q) is Not and type(q.formula) is Atom:  # type: ignore[attr-defined]
                        a = q.formula  # type: ignore[attr-defined]
                        i = ids.get((a.predicate, a.args))
                        if i is None:
                            alts = None  # an unreached atom's negation: the disjunction holds
                            break
                        alts.append(frozenset((~i,)))  # type: ignore[union-attr]
                        continue
                    hit = cache.get((id(q), "alt"))
                    if hit is None:
                        alt = _alternative(q, ids)
                        hit = cache[(id(q), "alt")] = (q, alt if alt is None else frozenset(alt))
                    conj = hit[1]
                    if conj is None:
                        continue
                    if not conj:
                        alts = None  # a true alternative: the disjunction holds
                        break
                    alts.append(conj)  # type: ignore[union-attr,arg-type]
                if alts is None:
                    continue
                if not alts:
                    return False
                choices.append(alts)
            elif isinstance(p, Atom):
                i = ids.get((p.predicate, p.args))
                if i is None:
                    return False
                literals.append(i)
            elif isinstance(p, Not) and isinstance(p.formula, Atom):
                i = ids.get((p.formula.predicate, p.formula.args))
                if i is not None:
                    literals.append(~i)
            else:
                return None
    except TypeError:
        return None
    return literals, choices


def fast_dnf(formula: Formula, ids: dict[AtomKey, int], cache: FormulaCache) -> list[IdConjunction] | None:
    """``minimal_dnf(prune(formula))`` over atom-id literals, for conjunctions of literals and of
    disjunctions of such (nearly all ground preconditions); None for any other shape.

    ``ids`` numbers the reached fluent atoms (a ground precondition has no static atom), so an atom
    without an id is unreachable. Compound conjuncts are scanned once per object (``cache``).
    """
    literals: list[int] = []
    choices: list[list[IdConjunction]] = []
    for p in formula.parts if isinstance(formula, And) else (formula,):
        if isinstance(p, Atom):
            i = ids.get((p.predicate, p.args))
            if i is None:
                return []
            literals.append(i)
            continue
        if isinstance(p, Not) and isinstance(p.formula, Atom):
            i = ids.get((p.formula.predicate, p.formula.args))
            if i is not None:
                literals.append(~i)
            continue
        if isinstance(p, (And, Or)):
            hit = cache.get(id(p))
            if hit is None:
                hit = cache[id(p)] = (p, _scan(p, ids, cache))
            found = hit[1]
        else:
            found = None
        if found is None:
            return None
        if found is False:
            return []
        literals += found[0]  # type: ignore[index]
        choices += found[1]  # type: ignore[index]
    return expand_dnf(literals, choices)


def expand_dnf(literals: list[int], choices: list[list[IdConjunction]]) -> list[IdConjunction] | None:
    """The minimal DNF of a conjunction of id literals and of choices between id conjunctions:
    every consistent pick of one alternative per choice with the literals, those containing
    another dropped; None beyond DNF_LIMIT disjuncts (the general path reports it)."""
    base = frozenset(literals)
    if not base.isdisjoint(map(invert, base)):  # a literal and its negation: no disjunct
        return []
    if not choices:
        return [base]
    acc = [base]
    for alts in choices:
        nxt: list[IdConjunction] = []
        seen: set[IdConjunction] = set()
        for left in acc:
            for right in alts:
                merged = left | right
                if merged in seen or not merged.isdisjoint(map(invert, right)):
                    continue
                seen.add(merged)
                nxt.append(merged)
        if len(nxt) > DNF_LIMIT:
            return None  # the general path reports it
        acc = nxt
    acc.sort(key=len)
    kept: list[IdConjunction] = []
    for d in acc:
        if not any(k <= d for k in kept):
            kept.append(d)
    return kept


def id_dnf(formula: Formula, reached: set[Atom], ids: dict[AtomKey, int]) -> list[IdConjunction]:
    """The general path of fast_dnf (any NNF shape), over atom-id literals."""
    out = []
    for conj in minimal_dnf(prune(formula, reached)):
        keyed = [((a.predicate, a.args), pos) for a, pos in conj]
        out.append(frozenset(ids[k] if pos else ~ids[k] for k, pos in keyed if k in ids))
    return out


def minimal_dnf(formula: Formula) -> list[Conjunction]:
    """DNF without subsumed disjuncts (a superset of another disjunct adds no operator worth having)."""
    disjuncts = sorted(to_dnf(formula), key=len)
    kept: list[Conjunction] = []
    for d in disjuncts:
        if not any(k <= d for k in kept):
            kept.append(d)
    return kept
