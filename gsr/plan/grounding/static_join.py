"""Static disjunctions joined while listing bindings, instead of ruled out binding by binding.

A precondition conjunct that is a disjunction over static predicates only, e.g. push's "?from and
?to are parts of one thing"::

    (or (part_of ?to ?from) (part_of ?from ?to)
        (exists (?t - thing) (and (part_of ?from ?t) (part_of ?to ?t))))

holds, for a problem, only for the value tuples of its free variables that the initial atoms give
(static atoms never change). When every disjunct is a conjunction of positive static atoms (under
at most one ``exists``) that mentions all those variables, the tuples are the union of the joins
of the disjuncts over the initial atoms, projected on the variables: a *relation* that the listing
joins like one more join atom (a pseudo-predicate no PDDL name can spell). Bindings outside it are
never listed; those inside are still checked by the precondition, so the relation only needs to be
a superset (quantified variables' types are not checked here) and the ground task is unchanged.
"""

from __future__ import annotations

from gsr.pddl.model import And, Atom, Exists, Formula, Or, is_variable
from gsr.plan.grounding.normalize import EQUALS

# One disjunct: its conjunction of static atoms (quantified variables are just more variables).
Disjunct = tuple[Atom, ...]
# A joinable static disjunction: the pseudo-atom over its free variables, and its disjuncts.
StaticJoin = tuple[Atom, tuple[Disjunct, ...]]

# Tuples scanned per relation before giving up (the listing then tests it per binding as before):
# a join of big static predicates without shared variables must not cost more than it saves.
WORK_LIMIT = 20_000


def _flat(formula: Formula, kind: type) -> list[Formula]:
    if isinstance(formula, kind):
        return [q for p in formula.parts for q in _flat(p, kind)]  # type: ignore[attr-defined]
    return [formula]


def static_join(part: Formula, free: tuple[str, ...], name: str) -> StaticJoin | None:
    """The StaticJoin of a static disjunction over ``free`` (pseudo-predicate ``name``), or None when a
    disjunct is not a conjunction of positive atoms mentioning every variable of ``free``."""
    disjuncts: list[Disjunct] = []
    for d in _flat(part, Or):
        if isinstance(d, Exists):
            d = d.body
        conj = _flat(d, And)
        if not all(type(a) is Atom and a.predicate != EQUALS for a in conj):
            return None
        mentioned = {x for a in conj for x in a.args if is_variable(x)}  # type: ignore[union-attr]
        if not mentioned >= set(free):
            return None
        disjuncts.append(tuple(conj))  # type: ignore[arg-type]
    if not disjuncts:
        return None
    return Atom(name, free), tuple(disjuncts)


def relation(join: StaticJoin, index: dict[str, set[tuple[str, ...]]]) -> set[tuple[str, ...]] | None:
    """The value tuples of a StaticJoin's variables under which some disjunct's atoms are all in
    ``index`` (the initial atoms by predicate); None past WORK_LIMIT scanned tuples."""
    head, disjuncts = join
    out: set[tuple[str, ...]] = set()
    work = [0]

    def rec(todo: Disjunct, binding: dict[str, str]) -> bool:
        if not todo:
            out.add(tuple(binding[x] for x in head.args))
            return True
        atom, rest = todo[0], todo[1:]
        for tup in index.get(atom.predicate, ()):
            work[0] += 1
            if work[0] > WORK_LIMIT:
                return False
            if len(tup) != len(atom.args):
                continue
            nb = binding
            for x, v in zip(atom.args, tup, strict=True):
                if is_variable(x):
                    bound = nb.get(x)
                    if bound is None:
                        if nb is binding:
                            nb = dict(binding)
                        nb[x] = v
                    elif bound != v:
                        break
                elif x != v:
                    break
            else:
                if not rec(rest, nb):
                    return False
        return True

    for conj in disjuncts:
        if not rec(conj, {}):
            return None
    return out
