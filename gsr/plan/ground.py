"""Grounding: relaxed-reachability fixpoint, static-predicate pruning and interning into a Task."""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    And,
    Atom,
    Domain,
    Equals,
    Formula,
    Increase,
    Not,
    Or,
    Problem,
    TypedVar,
    is_variable,
)
from gsr.plan.normalize import (
    Conjunction,
    Schema,
    nnf,
    normalize_action,
    to_dnf,
)
from gsr.plan.precondition import AtomKey, FormulaCache, fast_dnf, id_dnf, relaxed, relaxed_core
from gsr.plan.simplify import Simplifier, free_variables
from gsr.plan.task import GroundOp, Task

# Ground effects come in blocks (base, parts), each part (inner, atoms): every (atom, is_delete) of
# a part takes effect under the union of base and inner. The parts list of a memoised effect group
# is shared by every action with the same values of the variables it mentions (pick's cube counting
# by ?from), so its atoms are grounded, and later interned, once for all of them.
# Effect atoms are (predicate, args) keys (AtomKey), not Atom objects: they are hashed a few times
# each (reached test, interning) and tuples hash and compare in C; the few that get reached become
# Atoms then. Look-ups of Atoms go through their keys for the same reason.
EffectPart = tuple[Conjunction, tuple[tuple[AtomKey, bool], ...]]
EffectBlock = tuple[Conjunction, list[EffectPart]]
EffectMemo = dict[tuple, tuple[list[EffectPart], frozenset[Atom]]]
EMPTY: Conjunction = frozenset()


@dataclass(slots=True)
class _Variant:
    """A ground action: its simplified precondition formula; effects are grounded once it fires."""

    name: str
    args: tuple[str, ...]
    pre: Formula
    binding: dict[str, str]
    schema: Schema
    need: Formula  # what the delete relaxation tests of ``pre`` (see relaxed_core)
    effects: list[EffectBlock] | None = None
    fired: bool = False


def _conjuncts(formula: Formula) -> list[Formula]:
    """The conjuncts of a (nested) conjunction."""
    if isinstance(formula, And):
        return [q for p in formula.parts for q in _conjuncts(p)]
    return [formula]


def _any_reached(
    alternatives: list[tuple[Formula, ...]], binding: dict[str, str], reached: set[AtomKey]
) -> bool:
    """Whether each disjunction of atoms has a reached (or static initial) atom under ``binding``."""
    for atoms in alternatives:
        for a in atoms:
            if (a.predicate, tuple(map(binding.get, a.args, a.args))) in reached:  # type: ignore[union-attr]
                break
        else:
            return False
    return True


def _ruled_out(
    si: int,
    parts: list[tuple[Formula, tuple[str, ...]]],
    binding: dict[str, str],
    simplify: Simplifier,
    memo: dict[tuple, bool],
) -> bool:
    """Whether one of the narrow disjunctions is statically false under ``binding`` (memoised)."""
    for k, (part, free) in enumerate(parts):
        key = (si, k, *(binding[v] for v in free))
        false = memo.get(key)
        if false is None:
            false = memo[key] = simplify(part, binding) is FALSE
        if false:
            return True
    return False


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


# Reached and initial atoms by (predicate, argument position, value): a join atom with a bound
# argument scans only the atoms with that value there (pick's ``(on ?o ?from)`` once ``?o`` is bound).
ArgIndex = dict[tuple[str, int, str], list[tuple[str, ...]]]


def _index_atom(index: dict[str, set[tuple[str, ...]]], by_arg: ArgIndex, atom: Atom) -> None:
    """Add a new atom to both indexes."""
    index.setdefault(atom.predicate, set()).add(atom.args)
    for k, v in enumerate(atom.args):
        key = (atom.predicate, k, v)
        found = by_arg.get(key)
        if found is None:
            by_arg[key] = [atom.args]
        else:
            found.append(atom.args)


def _bindings(
    schema: Schema,
    index: dict[str, set[tuple[str, ...]]],
    objects: _TypedObjects,
    disjunction: tuple[Atom, ...] = (),
    by_arg: ArgIndex | None = None,
) -> list[dict]:
    """All parameter bindings whose join atoms hold in the (relaxed) reached set, typed.

    With a ``disjunction`` of atoms (pick's ``(or (on ?o ?from) (in ?o ?from))``), only bindings
    under which one of its atoms holds are listed: each alternative is joined like a join atom
    instead of enumerating every object for the variables it binds and testing it afterwards.
    """
    params = schema.all_params
    # The objects each parameter may take (typed); None for a variable that is no parameter.
    allowed: dict[str, frozenset[str]] = {}
    for p in params:
        objects(p.types)
        allowed[p.name] = objects.sets[p.types]
    atoms = schema.join
    out: list[dict] = []
    seen: set[tuple[str, ...]] = set()
    # Per atom: its arguments with whether each is a variable (looked at for every tuple).
    specs = {id(a): tuple((x, is_variable(x)) for x in a.args) for a in (*atoms, *disjunction)}

    def finish(binding: dict[str, str]) -> None:
        free = [p for p in params if p.name not in binding]
        if not free:  # the usual case: the join bound every parameter (a fresh dict per match)
            if disjunction:  # a binding may satisfy several alternatives
                key = tuple(binding[p.name] for p in params)
                if key in seen:
                    return
                seen.add(key)
            out.append(binding)
            return
        for combo in itertools.product(*(objects(p.types) for p in free)):
            full = dict(binding)
            full.update(zip((p.name for p in free), combo, strict=True))
            if disjunction:
                key = tuple(full[p.name] for p in params)
                if key in seen:
                    continue
                seen.add(key)
            out.append(full)

    def matches(atom: Atom, binding: dict[str, str]) -> Iterator[dict[str, str]]:
        spec = specs[id(atom)]
        tuples: Iterable[tuple[str, ...]] | None = None
        if by_arg is not None:
            for k, (a, var) in enumerate(spec):
                v = binding.get(a) if var else a
                if v is not None:
                    tuples = by_arg.get((atom.predicate, k, v), ())
                    break
        if tuples is None:
            tuples = index.get(atom.predicate, ())
        arity = len(spec)
        for tup in tuples:
            if len(tup) != arity:
                continue
            nb = binding
            for (a, var), v in zip(spec, tup, strict=False):  # arity checked above
                if var:
                    bound = nb.get(a)
                    if bound is None:
                        ok = allowed.get(a)
                        if ok is None or v not in ok:
                            break
                        if nb is binding:
                            nb = dict(binding)
                        nb[a] = v
                    elif bound != v:
                        break
                elif a != v:
                    break
            else:
                yield nb

    def rec(k: int, binding: dict[str, str]) -> None:
        if k == len(atoms):
            if not disjunction:
                finish(binding)
                return
            for alt in disjunction:
                for nb in matches(alt, binding):
                    finish(nb)
            return
        for nb in matches(atoms[k], binding):
            rec(k + 1, nb)

    rec(0, {})
    return out


def _disjunction(schema: Schema, alternatives: list[tuple[Formula, ...]]) -> tuple[Atom, ...]:
    """The first top-level disjunction of atoms each binding a variable the join atoms leave free."""
    bound = {a for atom in schema.join for a in atom.args if is_variable(a)}
    for alts in alternatives:
        if all(isinstance(q, Atom) and any(is_variable(a) and a not in bound for a in q.args) for q in alts):
            return alts  # type: ignore[return-value]
    return ()


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


# A precondition conjunct, its free variables if fewer than the action's (memo key), and its kind:
# the common shapes are grounded directly instead of through the Simplifier.
Part = tuple[Formula, tuple[str, ...] | None, int]
_GENERIC, _SKIP, _FLUENT, _NOT_FLUENT, _DISTINCT = range(5)


def _part_kind(part: Formula, join: bool, fluent: set[str]) -> int:
    """How ``_variant`` grounds one conjunct (see Part)."""
    if isinstance(part, Atom):
        if part.predicate in fluent:
            return _FLUENT
        # A static join atom holds for every listed binding: the join matched it in the initial state.
        return _SKIP if join else _GENERIC
    if isinstance(part, Not) and isinstance(part.formula, Atom) and part.formula.predicate in fluent:
        return _NOT_FLUENT
    if isinstance(part, Not) and isinstance(part.formula, Equals):
        return _DISTINCT
    return _GENERIC


def _parts(schema: Schema, fluent: set[str]) -> list[Part]:
    """The precondition conjuncts with their memo keys and kinds (see Part)."""
    n = len(schema.all_params)
    out: list[Part] = []
    for k, part in enumerate((*schema.join, *_conjuncts(schema.residual))):
        free = free_variables(part)
        memo = tuple(sorted(free)) if len(free) < n and not isinstance(part, Atom) else None
        out.append((part, memo, _part_kind(part, k < len(schema.join), fluent)))
    return out


def _variant(
    schema: Schema,
    si: int,
    parts: list[Part],
    binding: dict[str, str],
    simplify: Simplifier,
    memo: dict[tuple, Formula],
    cores: FormulaCache,
) -> _Variant | None:
    """Ground one action's precondition; None when it is statically false.

    Conjuncts over fewer variables than the action (``(imply (openable ?c) (open ?c))`` in
    place_in) are simplified once per value of their variables.
    """
    kept: list[Formula] = []
    core: list[Formula] = []  # the relaxed core of each kept conjunct (see relaxed_core)
    for k, (part, free, kind) in enumerate(parts):
        if kind == _FLUENT:
            g = Atom(part.predicate, tuple(map(binding.get, part.args, part.args)))  # type: ignore[union-attr]
            kept.append(g)
            core.append(g)
            continue
        if kind == _NOT_FLUENT:
            a = part.formula  # type: ignore[union-attr]
            kept.append(Not(Atom(a.predicate, tuple(map(binding.get, a.args, a.args)))))
            continue
        if kind == _DISTINCT:
            eq = part.formula  # type: ignore[union-attr]
            left, right = binding.get(eq.left, eq.left), binding.get(eq.right, eq.right)
            if left.startswith("?") or right.startswith("?"):
                raise GSRError(f"free variable in equality ({left} = {right})")
            if left == right:
                return None
            continue
        if kind == _SKIP:
            continue
        if free is None:
            g = simplify(part, binding)
        else:
            key = (si, k, *(binding.get(v, v) for v in free))
            g = memo.get(key)  # type: ignore[assignment]
            if g is None:
                g = memo[key] = simplify(part, binding)
        if g is FALSE:
            return None
        if g is not TRUE:
            kept.append(g)
            c = relaxed_core(g, cores)
            if c is not TRUE:
                core.append(c)
    pre = Simplifier.combine(True, kept)
    need = Simplifier.combine(True, core)
    args = tuple(binding[p.name] for p in schema.params)
    return _Variant(schema.name, args, pre, binding, schema, need)


Literals = tuple[tuple[Atom, bool], ...]
# (params, condition, guards, (outer, inner) literals or None, effect atoms with is_delete,
# action variables the per-instance part mentions)
_EffectGroup = tuple[
    tuple[TypedVar, ...],
    Formula,
    tuple[Atom, ...],
    tuple[Literals, Literals] | None,
    Literals,
    tuple[str, ...],
]


def _effect_groups(schema: Schema, simplify: Simplifier) -> list[_EffectGroup]:
    """Effects sharing variables and condition, grouped: (params, condition, guards, literals, atoms).

    ``forall ?n ?m (when c (and (not (cube_count ?c ?n)) (cube_count ?c ?m)))`` flattens into two
    effects with one condition; grouping grounds the instances and the condition once for both.
    A condition that is a conjunction of literals is split into the literals without effect
    variables (grounded once per action binding) and the rest (per instance); positive static
    literals over effect variables are dropped, since instances come from joining exactly those.
    """
    groups: dict[tuple, list[tuple[Atom, bool]]] = {}
    for eff in schema.effects:
        groups.setdefault((eff.params, eff.condition), []).append((eff.literal.atom, eff.literal.negated))
    out: list[_EffectGroup] = []
    for (params, cond), lits in groups.items():
        literals = simplify.literals(cond)
        split = None
        if literals is not None:
            names = {p.name for p in params}
            outer = tuple((a, pos) for a, pos in literals if not names.intersection(a.args))
            inner = tuple(
                (a, pos)
                for a, pos in literals
                if names.intersection(a.args) and not (pos and a.predicate not in simplify.fluent)
            )
            split = (outer, inner)
        guards = simplify.guards(cond, True) if params else ()
        # Action variables the per-instance part mentions: its memo key (see _ground_group).
        # Guards without effect variables are checked once per binding, in base/instances.
        names = {p.name for p in params}
        atoms = [g for g in guards if names.intersection(g.args)]
        atoms += [a for a, _ in split[1]] if split else []
        atoms += [a for a, _ in lits]
        used = tuple(sorted({x for a in atoms for x in a.args if is_variable(x) and x not in names}))
        out.append((params, cond, guards, split, tuple(lits), used))
    return out


Deferred = tuple["_Variant", _EffectGroup, dict[str, str], Conjunction]


def _effects(
    v: _Variant,
    groups: list[_EffectGroup],
    simplify: Simplifier,
    reached: set[AtomKey],
    deferred: list[Deferred],
    memo: EffectMemo,
) -> None:
    """Ground a fired action's effects into ``v.effects`` (see EffectBlock).

    A group whose binding-level condition needs an atom not reached yet (pick's cube counting
    ``(in ?o ?from)`` for an object on the table) is deferred: it is grounded once that atom is
    reached, or never, which is what interning would make of its effects anyway.
    """
    v.effects = []
    for group in groups:
        split = group[3]
        base = None
        if split is not None:
            base = simplify.ground_literals(split[0], v.binding)
            if base is None:
                continue  # the condition is false whatever the effect variables are
            if any(pos and (a.predicate, a.args) not in reached for a, pos in base):
                deferred.append((v, group, v.binding, base))
                continue
        _ground_group(group, v.binding, base, simplify, v.effects, memo)


def _ground_group(
    group: _EffectGroup,
    binding: dict[str, str],
    base: Conjunction | None,
    simplify: Simplifier,
    effects: list[EffectBlock],
    memo: EffectMemo | None = None,
) -> None:
    """Append the ground effects of one effect group (``base``: its grounded binding-level literals).

    With ``memo``, the per-instance part of a literal condition (instances, their literals and
    effect atoms) is grounded once per value of the action variables it mentions: pick's cube
    counting depends on ``?from`` only, not on the object picked.
    """
    params, condition, guards, split, lits, _used = group
    if split == ((), ()) and not params:
        # Unconditional: never worth memoising (the atoms mention the action's variables).
        ground = tuple(((a.predicate, tuple(map(binding.get, a.args, a.args))), d) for a, d in lits)
        effects.append((EMPTY, [(EMPTY, ground)]))
        return
    if split is not None and base is not None and memo is not None:
        key = (id(group), *(binding.get(v, v) for v in group[5]))
        entry = memo.get(key)
        if entry is None:
            parts: list[EffectPart] = []
            instances = simplify.instances(params, guards, binding) if params else (binding,)
            for b in instances:
                inner = simplify.ground_literals(split[1], b) if split[1] else frozenset()
                if inner is None:
                    continue
                ground = tuple(
                    ((atom.predicate, tuple(map(b.get, atom.args, atom.args))), is_del)
                    for atom, is_del in lits
                )
                parts.append((inner, ground))
            entry = memo[key] = (parts, frozenset(a for inner, _ in parts for a, _ in inner))
        parts, inner_atoms = entry
        if base and not inner_atoms.isdisjoint([a for a, _ in base]):
            # Parts whose condition contradicts the base never fire: this action gets its own list.
            parts = [(inner, g) for inner, g in parts if not any((a, not pos) in base for a, pos in inner)]
        if parts:
            effects.append((base, parts))
        return
    # Effect variables range only over objects satisfying the condition's static atoms.
    instances = simplify.instances(params, guards, binding) if params else (binding,)
    own: list[EffectPart] = []
    for b in instances:
        if split is not None and base is not None:  # the common case: a conjunction of literals
            conj = simplify.ground_literals(split[1], b) if split[1] else base
            if conj is None:
                continue
            if conj is not base:
                if any((a, not pos) in base for a, pos in conj):
                    continue
                conj = base | conj
            conjs: list[Conjunction] = [conj]
        else:
            conjs = to_dnf(simplify(condition, b))
        ground = tuple(
            ((atom.predicate, tuple(map(b.get, atom.args, atom.args))), is_del) for atom, is_del in lits
        )
        own.extend((conj, ground) for conj in conjs)
    if own:
        effects.append((EMPTY, own))


def _new_adds(
    blocks: list[EffectBlock], reached: set[AtomKey], pending: list[tuple[tuple[AtomKey, ...], AtomKey]]
) -> None:
    """Queue the add effects not reached yet with their positive condition atoms (see ground_task)."""
    for base, parts in blocks:
        outer: tuple[Atom, ...] | None = None
        for inner, ground in parts:
            for atom, is_del in ground:
                if not is_del and atom not in reached:
                    if outer is None:
                        outer = tuple((a.predicate, a.args) for a, pos in base if pos)
                    pending.append((outer + tuple((a.predicate, a.args) for a, pos in inner if pos), atom))


@dataclass(frozen=True, slots=True)
class _Compiled:
    """What grounding derives from a domain alone: normalised schemas and their per-schema tables."""

    schemas: list[Schema]
    fluent: set[str]
    groups: list[list[_EffectGroup]]
    alternatives: list[list[tuple[Formula, ...]]]
    narrow: list[list[tuple[Formula, tuple[str, ...]]]]
    parts: list[list[Part]]
    disjunctions: list[tuple[Atom, ...]]  # joined while listing bindings (see _bindings)
    triggers: list[tuple[str, ...]]  # predicates whose growth can give a schema new bindings


# The few most recent domains, by identity (load_builtin_domain hands out one cached object, so a
# run of plan() calls on one domain compiles its schemas once). The domain is kept in the entry so
# that its id stays valid; domains are treated as immutable, like the rest of gsr.pddl.model.
_COMPILED: list[tuple[Domain, _Compiled]] = []
_COMPILED_MAX = 4


def _compile(domain: Domain) -> _Compiled:
    """The domain-only grounding tables of ``domain`` (memoised on its identity)."""
    for known, compiled in _COMPILED:
        if known is domain:
            return compiled
    schemas = [normalize_action(a) for a in domain.actions.values()]
    fluent = {e.literal.atom.predicate for s in schemas for e in s.effects}
    # Effect groups need only the fluent predicates (literal splitting, static guards).
    no_objects = Simplifier(_TypedObjects(domain, {}), fluent, ())
    compiled = _Compiled(
        schemas,
        fluent,
        [_effect_groups(s, no_objects) for s in schemas],
        # Top-level disjunctions of atoms in each residual precondition, e.g. pick's (or (on ?o
        # ?from) (in ?o ?from)): a binding with none of them reached cannot fire yet, so it is
        # skipped before its precondition is simplified (and looked at again next round).
        [
            [
                part.parts
                for part in _conjuncts(s.residual)
                if isinstance(part, Or) and part.parts and all(isinstance(q, Atom) for q in part.parts)
            ]
            for s in schemas
        ],
        # Top-level disjunctions over fewer variables than the action (push's "?to and ?from are
        # parts of one thing"): simplified once per value of their variables; a false one rules
        # the binding out.
        [
            [
                (part, tuple(sorted(free_variables(part))))
                for part in _conjuncts(s.residual)
                if isinstance(part, Or) and len(free_variables(part)) < len(s.all_params)
            ]
            for s in schemas
        ],
        [_parts(s, fluent) for s in schemas],
        [],
        [],
    )
    for s, alts in zip(schemas, compiled.alternatives, strict=True):
        disjunction = _disjunction(s, alts)
        if disjunction:
            alts.remove(disjunction)  # holds for every listed binding: no need to test it again
        compiled.disjunctions.append(disjunction)
        compiled.triggers.append(tuple(a.predicate for a in (*s.join, *disjunction)))
    _COMPILED.insert(0, (domain, compiled))
    del _COMPILED[_COMPILED_MAX:]
    return compiled


def ground_task(domain: Domain, problem: Problem) -> Task:
    """Ground a problem: only relaxed-reachable operators, static atoms compiled away."""
    objects = _TypedObjects(domain, problem.all_objects(domain))
    compiled = _compile(domain)
    schemas, fluent = compiled.schemas, compiled.fluent
    init = set(problem.init)
    simplify = Simplifier(objects, fluent, init)

    reached: set[Atom] = set(init)
    index: dict[str, set[tuple[str, ...]]] = {}
    by_arg: ArgIndex = {}
    for a in init:
        _index_atom(index, by_arg, a)
    groups, alternatives, narrow, parts = (
        compiled.groups,
        compiled.alternatives,
        compiled.narrow,
        compiled.parts,
    )
    disjunctions, triggers = compiled.disjunctions, compiled.triggers
    narrow_memo: dict[tuple, bool] = {}
    part_memo: dict[tuple, Formula] = {}
    cores: FormulaCache = {}
    cache: dict[tuple, _Variant | None] = {}
    fired: list[_Variant] = []
    # Add effects of fired operators not reached yet: (positive condition atoms, atom key). Each
    # round only scans these, not every effect of every fired operator again.
    pending: list[tuple[tuple[AtomKey, ...], AtomKey]] = []
    reached_keys: set[AtomKey] = {(a.predicate, a.args) for a in init}
    deferred: list[Deferred] = []
    effect_memo: EffectMemo = {}
    join_sizes: list[tuple[int, ...] | None] = [None] * len(schemas)
    unfired: list[list[dict[str, str]]] = [[] for _ in schemas]
    changed = True
    while changed:
        changed = False
        for si, schema in enumerate(schemas):
            names = [p.name for p in schema.all_params]
            # Bindings depend only on the join predicates' atoms: while those did not grow, only
            # the bindings that have not fired yet (and may now) are looked at again.
            sizes = tuple(len(index.get(p, ())) for p in triggers[si])
            if sizes == join_sizes[si]:
                candidates = unfired[si]
            else:
                join_sizes[si] = sizes
                candidates = _bindings(schema, index, objects, disjunctions[si], by_arg)
            unfired[si] = still = []
            for binding in candidates:
                key = (si, *(binding[n] for n in names))
                if key not in cache:
                    if narrow[si] and _ruled_out(si, narrow[si], binding, simplify, narrow_memo):
                        cache[key] = None
                        continue
                    if alternatives[si] and not _any_reached(alternatives[si], binding, reached_keys):
                        still.append(binding)
                        continue
                if key in cache:
                    v = cache[key]
                else:
                    v = cache[key] = _variant(schema, si, parts[si], binding, simplify, part_memo, cores)
                if v is None or v.fired:
                    continue
                if not relaxed(v.need, reached_keys):
                    still.append(binding)
                else:
                    v.fired = True
                    _effects(v, groups[si], simplify, reached_keys, deferred, effect_memo)
                    fired.append(v)
                    _new_adds(v.effects, reached_keys, pending)
        # Deferred effect groups whose binding-level condition is now reached get grounded.
        blocked = []
        for v, group, binding, base in deferred:
            if any(pos and (a.predicate, a.args) not in reached_keys for a, pos in base):
                blocked.append((v, group, binding, base))
                continue
            start = len(v.effects)
            _ground_group(group, binding, base, simplify, v.effects, effect_memo)
            _new_adds(v.effects[start:], reached_keys, pending)
        deferred = blocked
        # Fire the add effects of reached operators whose (positive) conditions are reached.
        waiting = []
        for cond, key in pending:
            if key in reached_keys:
                continue
            if all(c in reached_keys for c in cond):
                atom = Atom(*key)
                reached.add(atom)
                reached_keys.add(key)
                _index_atom(index, by_arg, atom)
                changed = True
            else:
                waiting.append((cond, key))
        pending = waiting
    return _intern(domain, problem, fired, reached, fluent)


def _condition_ids(
    cond: Conjunction, ids: dict[AtomKey, int]
) -> tuple[tuple[int, ...], tuple[int, ...]] | tuple[()]:
    """(positive ids, negative ids) of a condition, sorted; () when it needs an unreached atom."""
    pos_ids: list[int] = []
    neg_ids: list[int] = []
    for a, pos in cond:
        i = ids.get((a.predicate, a.args))
        if pos:
            if i is None:
                return ()
            pos_ids.append(i)
        elif i is not None:
            neg_ids.append(i)
    return (tuple(sorted(pos_ids)), tuple(sorted(neg_ids)))


# An effect part over atom ids: (condition positive ids, condition negative ids, add ids, delete
# ids), all sorted; with the set of condition ids of all parts of its list.
_PartIds = tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...], tuple[int, ...]]


def _parts_ids(parts: list[EffectPart], key_ids: dict[AtomKey, int]) -> tuple[list[_PartIds], frozenset[int]]:
    """Effect parts over atom ids; parts needing, or changing only, never-reached atoms dropped."""
    out: list[_PartIds] = []
    for inner, ground in parts:
        r = _condition_ids(inner, key_ids) if inner else ((), ())
        if not r:
            continue
        adds = tuple(i for a, is_del in ground if not is_del and (i := key_ids.get(a)) is not None)
        dels = tuple(i for a, is_del in ground if is_del and (i := key_ids.get(a)) is not None)
        if adds or dels:
            out.append((r[0], r[1], adds, dels))
    return out, frozenset(i for r0, r1, _, _ in out for i in (*r0, *r1))


def _filtered_parts(
    conv: list[_PartIds], pre: set[int], neg: set[int]
) -> tuple[list[_PartIds], list[_PartIds]]:
    """The parts whose condition is consistent with a precondition, minus its literals: those left
    without a condition, and the others."""
    plain: list[_PartIds] = []
    conditional: list[_PartIds] = []
    for r0, r1, adds, dels in conv:
        if not neg.isdisjoint(r0) or not pre.isdisjoint(r1):
            continue  # contradicts the precondition: never fires
        rp = r0 if pre.isdisjoint(r0) else tuple(i for i in r0 if i not in pre)
        rn = r1 if neg.isdisjoint(r1) else tuple(i for i in r1 if i not in neg)
        (conditional if rp or rn else plain).append((rp, rn, adds, dels))
    return plain, conditional


def _cond_table(
    blocks: list[tuple[tuple[list[_PartIds], list[_PartIds]], tuple[int, ...], tuple[int, ...]]],
) -> tuple[tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...], tuple[int, ...]], ...]:
    """GroundOp.cond of the conditional blocks: effects merged by condition, sorted."""
    cond: dict[tuple[tuple[int, ...], tuple[int, ...]], tuple[set[int], set[int]]] = {}
    for (plain, conditional), bp, bn in blocks:
        for rp, rn, adds, dels in (*plain, *conditional) if bp or bn else conditional:
            cp = (tuple(sorted({*bp, *rp})) if rp else bp) if bp else rp
            cn = (tuple(sorted({*bn, *rn})) if rn else bn) if bn else rn
            target = cond.get((cp, cn))
            if target is None:
                target = cond[(cp, cn)] = (set(), set())
            target[0].update(adds)
            target[1].update(dels)
    return tuple(
        (cp, cn, tuple(sorted(a)), tuple(sorted(d - a))) for (cp, cn), (a, d) in sorted(cond.items())
    )


def _intern(
    domain: Domain, problem: Problem, fired: list[_Variant], reached: set[Atom], fluent: set[str]
) -> Task:
    atoms = sorted((a for a in reached if a.predicate in fluent), key=lambda a: (a.predicate, a.args))
    ids = {a: i for i, a in enumerate(atoms)}
    key_ids = {(a.predicate, a.args): i for i, a in enumerate(atoms)}
    ops: set[GroundOp] = set()
    # Condition parts over atom ids, by object (parts are shared by many effects and actions;
    # every part is referenced from the fired actions, so ids stay unique).
    converted: dict[int, tuple[tuple[int, ...], tuple[int, ...]] | tuple[()]] = {}
    scanned: FormulaCache = {}  # DNF parts of the shared precondition conjuncts
    parts_ids: dict[int, tuple[list[EffectPart], list[_PartIds], frozenset[int]]] = {}  # by list
    filtered: dict[tuple, tuple[list[_PartIds], list[_PartIds]]] = {}  # see _filtered_parts
    cond_tables: dict[tuple, tuple] = {}  # see _cond_table
    for v in fired:
        disjuncts = fast_dnf(v.pre, key_ids, scanned)
        if disjuncts is None:
            disjuncts = id_dnf(v.pre, reached, key_ids)
        if not disjuncts:
            continue
        # The variant's effect blocks over atom ids; effects on never-reached atoms, or needing
        # one, never matter.
        blocks = []
        for base, parts in v.effects or ():
            b = converted.get(id(base))
            if b is None:
                b = converted[id(base)] = _condition_ids(base, key_ids)
            if not b:
                continue  # needs an atom never reached
            hit = parts_ids.get(id(parts))
            if hit is None:
                hit = parts_ids[id(parts)] = (parts, *_parts_ids(parts, key_ids))
            if hit[1]:
                blocks.append((b, hit))
        for disjunct in disjuncts:
            pre = tuple(sorted(x for x in disjunct if x >= 0))
            neg = tuple(sorted(~x for x in disjunct if x < 0))
            pre_set, neg_set = set(pre), set(neg)
            add: set[int] = set()
            dele: set[int] = set()
            # An effect takes effect under base | inner minus the precondition's literals; it never
            # fires when that contradicts the precondition (which is itself consistent). The parts
            # of a shared list are filtered once per intersection of the precondition with their
            # condition atoms (cube counting: once per container, not per cube picked).
            conditional = []  # (kept parts, base literals left) of the blocks with conditional effects
            for (b0, b1), (parts, conv, atoms_of) in blocks:
                if not neg_set.isdisjoint(b0) or not pre_set.isdisjoint(b1):
                    continue
                bp = b0 if pre_set.isdisjoint(b0) else tuple(i for i in b0 if i not in pre_set)
                bn = b1 if neg_set.isdisjoint(b1) else tuple(i for i in b1 if i not in neg_set)
                if atoms_of:
                    fkey = (id(parts), atoms_of & pre_set, atoms_of & neg_set)
                    kept = filtered.get(fkey)
                    if kept is None:
                        kept = filtered[fkey] = _filtered_parts(conv, pre_set, neg_set)
                else:
                    kept = (conv, [])  # unconditional parts: nothing to filter
                if bp or bn:
                    conditional.append((kept, bp, bn))
                    continue
                for _rp, _rn, adds, dels in kept[0]:
                    add.update(adds)
                    dele.update(dels)
                if kept[1]:
                    conditional.append((kept, bp, bn))
            # The conditional effects depend only on the kept parts and base literals left, which
            # many actions share (cube counting by container): converted once per combination.
            conds: tuple = ()
            if conditional:
                ckey = tuple((id(kept), bp, bn) for kept, bp, bn in conditional)
                found = cond_tables.get(ckey)
                if found is None:
                    found = cond_tables[ckey] = _cond_table(conditional)
                conds = found
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
