"""Grounding: relaxed-reachability fixpoint, static-predicate pruning and interning into a Task."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

from gsr.errors import GSRError
from gsr.pddl.model import FALSE, TRUE, And, Atom, Domain, Formula, Increase, Not, Or, Problem, is_variable
from gsr.plan.normalize import (
    Conjunction,
    Schema,
    nnf,
    normalize_action,
    to_dnf,
)
from gsr.plan.simplify import Simplifier
from gsr.plan.task import GroundOp, Task

GroundEffect = tuple[Conjunction, Atom, bool]  # (condition, atom, is_delete)


@dataclass(slots=True)
class _Variant:
    """A ground action: its simplified precondition formula; effects are grounded once it fires."""

    name: str
    args: tuple[str, ...]
    pre: Formula
    binding: dict[str, str]
    schema: Schema
    effects: list[GroundEffect] | None = None
    fired: bool = False


def _relaxed(formula: Formula, reached: set[Atom]) -> bool:
    """Whether a ground NNF formula can hold in the delete relaxation (negative literals ignored)."""
    if isinstance(formula, Atom):
        return formula in reached
    if isinstance(formula, And):
        return all(_relaxed(p, reached) for p in formula.parts)
    if isinstance(formula, Or):
        return any(_relaxed(p, reached) for p in formula.parts)
    return True  # a negative literal


def _prune(formula: Formula, reached: set[Atom]) -> Formula:
    """Unreachable atoms are false: simplify a ground NNF formula before its DNF is taken."""
    if isinstance(formula, Atom):
        return formula if formula in reached else FALSE
    if isinstance(formula, Not):
        return formula if formula.formula in reached else TRUE
    if isinstance(formula, (And, Or)):
        return Simplifier.combine(isinstance(formula, And), (_prune(p, reached) for p in formula.parts))
    return formula


def minimal_dnf(formula: Formula) -> list[Conjunction]:
    """DNF without subsumed disjuncts (a superset of another disjunct adds no operator worth having)."""
    disjuncts = sorted(to_dnf(formula), key=len)
    kept: list[Conjunction] = []
    for d in disjuncts:
        if not any(k <= d for k in kept):
            kept.append(d)
    return kept


class _TypedObjects:
    """Objects of a type (either-tuples allowed), cached and sorted for determinism."""

    def __init__(self, domain: Domain, objects: dict[str, str]) -> None:
        self.domain, self.objects = domain, objects
        self.cache: dict[tuple[str, ...], list[str]] = {}
        self.sets: dict[tuple[str, ...], frozenset[str]] = {}

    def __call__(self, types: tuple[str, ...]) -> list[str]:
        found = self.cache.get(types)
        if found is None:
            found = sorted(o for o, t in self.objects.items() if self.domain.is_subtype(t, types))
            self.cache[types] = found
            self.sets[types] = frozenset(found)
        return found

    def has(self, obj: str, types: tuple[str, ...]) -> bool:
        """True when ``obj`` is of one of ``types``."""
        if types not in self.sets:
            self(types)
        return obj in self.sets[types]


def _bindings(schema: Schema, index: dict[str, set[tuple[str, ...]]], objects: _TypedObjects) -> list[dict]:
    """All parameter bindings whose join atoms hold in the (relaxed) reached set, typed."""
    params = schema.all_params
    ptypes = {p.name: p.types for p in params}
    atoms = schema.join
    out: list[dict] = []

    def rec(k: int, binding: dict[str, str]) -> None:
        if k == len(atoms):
            free = [p for p in params if p.name not in binding]
            for combo in itertools.product(*(objects(p.types) for p in free)):
                full = dict(binding)
                full.update(zip((p.name for p in free), combo, strict=True))
                out.append(full)
            return
        atom = atoms[k]
        for tup in index.get(atom.predicate, ()):
            if len(tup) != len(atom.args):
                continue
            nb = binding
            for a, v in zip(atom.args, tup, strict=True):
                if is_variable(a):
                    bound = nb.get(a)
                    if bound is None:
                        types = ptypes.get(a)
                        if types is None or not objects.has(v, types):
                            break
                        if nb is binding:
                            nb = dict(binding)
                        nb[a] = v
                    elif bound != v:
                        break
                elif a != v:
                    break
            else:
                rec(k + 1, nb)

    rec(0, {})
    return out


def _cost(costs: tuple[Increase, ...], binding: dict[str, str], problem: Problem) -> float:
    """Action cost from ``(increase (total-cost) ...)`` when the problem has a metric, else 1."""
    if problem.metric is None:
        return 1.0
    total = 0.0
    for inc in costs:
        amount = inc.amount
        if isinstance(amount, (int, float)):
            total += float(amount)
            continue
        text = str(amount).strip().strip("()").split()
        try:
            total += float(text[0])
            continue
        except (ValueError, IndexError):
            pass
        key = Atom(text[0].lower(), tuple(binding.get(a, a) for a in text[1:]))
        if key not in problem.init_numeric:
            raise GSRError(f"action cost {amount} has no value in the problem's :init")
        total += problem.init_numeric[key]
    return total


def _variant(schema: Schema, binding: dict[str, str], simplify: Simplifier) -> _Variant | None:
    """Ground one action's precondition; None when it is statically false."""
    pre = simplify(And((*schema.join, schema.residual)), binding)
    if pre is FALSE:
        return None
    args = tuple(binding[p.name] for p in schema.params)
    return _Variant(schema.name, args, pre, binding, schema)


def _effects(schema: Schema, binding: dict[str, str], simplify: Simplifier) -> list[GroundEffect]:
    """A fired action's ground effects: (condition disjunct, atom, is_delete) triples."""
    effects: list[GroundEffect] = []
    for eff in schema.effects:
        # Effect variables range only over objects satisfying the condition's static atoms.
        guards = simplify.guards(eff.condition, True) if eff.params else ()
        instances = simplify.instances(eff.params, guards, binding) if eff.params else (binding,)
        literals = simplify.literals(eff.condition)
        atom = eff.literal.atom
        for b in instances:
            ground = Atom(atom.predicate, tuple(map(b.get, atom.args, atom.args)))
            if literals is not None:  # the common case: a conjunction of literals
                conj = simplify.ground_literals(literals, b)
                if conj is not None:
                    effects.append((conj, ground, eff.literal.negated))
                continue
            for conj in to_dnf(simplify(eff.condition, b)):
                effects.append((conj, ground, eff.literal.negated))
    return effects


def ground_task(domain: Domain, problem: Problem) -> Task:
    """Ground a problem: only relaxed-reachable operators, static atoms compiled away."""
    objects = _TypedObjects(domain, problem.all_objects(domain))
    schemas = [normalize_action(a) for a in domain.actions.values()]
    fluent = {e.literal.atom.predicate for s in schemas for e in s.effects}
    init = set(problem.init)
    simplify = Simplifier(objects, fluent, init)

    reached: set[Atom] = set(init)
    index: dict[str, set[tuple[str, ...]]] = {}
    for a in init:
        index.setdefault(a.predicate, set()).add(a.args)
    cache: dict[tuple, _Variant | None] = {}
    fired: list[_Variant] = []
    changed = True
    while changed:
        changed = False
        for si, schema in enumerate(schemas):
            names = [p.name for p in schema.all_params]
            for binding in _bindings(schema, index, objects):
                key = (si, *(binding[n] for n in names))
                if key in cache:
                    v = cache[key]
                else:
                    v = cache[key] = _variant(schema, binding, simplify)
                if v is not None and not v.fired and _relaxed(v.pre, reached):
                    v.fired = True
                    v.effects = _effects(schema, binding, simplify)
                    fired.append(v)
        # Fire the add effects of reached operators whose (positive) conditions are reached.
        for v in fired:
            for cond, atom, is_del in v.effects or ():
                if not is_del and atom not in reached and all(a in reached for a, pos in cond if pos):
                    reached.add(atom)
                    index.setdefault(atom.predicate, set()).add(atom.args)
                    changed = True
    return _intern(domain, problem, fired, reached, fluent)


def _intern(
    domain: Domain, problem: Problem, fired: list[_Variant], reached: set[Atom], fluent: set[str]
) -> Task:
    atoms = sorted((a for a in reached if a.predicate in fluent), key=lambda a: (a.predicate, a.args))
    ids = {a: i for i, a in enumerate(atoms)}
    ops: set[GroundOp] = set()
    for v, disjunct in ((f, d) for f in fired for d in minimal_dnf(_prune(f.pre, reached))):
        pre = tuple(sorted(ids[a] for a, pos in disjunct if pos and a in ids))
        neg = tuple(sorted(ids[a] for a, pos in disjunct if not pos and a in ids))
        pre_set, neg_set = set(pre), set(neg)
        add: set[int] = set()
        dele: set[int] = set()
        cond: dict[tuple[tuple[int, ...], tuple[int, ...]], tuple[set[int], set[int]]] = {}
        for c, atom, is_del in v.effects or ():
            if atom not in ids or any(pos and a not in ids for a, pos in c):
                continue  # never true / never fires
            cp = tuple(sorted(ids[a] for a, pos in c if pos and ids[a] not in pre_set))
            cn = tuple(sorted(ids[a] for a, pos in c if not pos and a in ids and ids[a] not in neg_set))
            if set(cp) & neg_set or set(cn) & pre_set:
                continue  # contradicts the precondition: never fires
            target = (add, dele) if not cp and not cn else cond.setdefault((cp, cn), (set(), set()))
            target[1 if is_del else 0].add(ids[atom])
        conds = tuple(
            (cp, cn, tuple(sorted(a)), tuple(sorted(d - a))) for (cp, cn), (a, d) in sorted(cond.items())
        )
        ops.add(
            GroundOp(
                v.name,
                v.args,
                _cost(v.schema.costs, v.binding, problem),
                pre,
                neg,
                tuple(sorted(add)),
                tuple(sorted(dele - add)),
                conds,
            )
        )
    ordered = sorted(ops, key=lambda o: (o.name, o.args, o.pre, o.neg, o.add, o.delete, o.cond))
    init = 0
    for a in problem.init:
        if a in ids:
            init |= 1 << ids[a]
    goals = ground_goal(domain, problem, problem.goal, ids, fluent)
    return Task(atoms, ordered, init, goals)


def ground_goal(
    domain: Domain, problem: Problem, goal: Formula, ids: dict[Atom, int], fluent: set[str]
) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """The goal as a DNF over atom ids; disjuncts needing unreachable atoms are dropped."""
    simplify = Simplifier(_TypedObjects(domain, problem.all_objects(domain)), fluent, problem.init)
    out = []
    for conj in to_dnf(simplify(nnf(goal), {})):
        if any(pos and a not in ids for a, pos in conj):
            continue
        pos_ids = tuple(sorted(ids[a] for a, pos in conj if pos))
        neg_ids = tuple(sorted(ids[a] for a, pos in conj if not pos and a in ids))
        out.append((pos_ids, neg_ids))
    return out
