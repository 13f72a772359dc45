"""The grounding fixpoint: relaxed reachability with static-predicate pruning, then interning into a Task.

The fixpoint lists bindings, grounds preconditions and fires actions here; effect grounding is in
gsr.plan.grounding.effects, interning into a Task in gsr.plan.grounding.intern.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from time import perf_counter

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    And,
    Atom,
    Domain,
    Equals,
    Formula,
    Not,
    Or,
    Problem,
    is_variable,
)
from gsr.pddl.walk import atoms as atoms_of
from gsr.plan.grounding.compiled import bind, compile_schema
from gsr.plan.grounding.compiled_effects import compile_effects
from gsr.plan.grounding.effects import (
    Deferred,
    EffectGroup,
    EffectMemo,
    Variant,
    effect_groups,
    ground_effects,
    ground_group,
    new_adds,
)
from gsr.plan.grounding.intern import axiom_action, intern_task
from gsr.plan.grounding.normalize import (
    EQUALS,
    Schema,
    normalize_action,
    split_cases,
)
from gsr.plan.grounding.precondition import AtomKey, FormulaCache, relaxed, relaxed_core
from gsr.plan.grounding.simplify import ObjectsByType, Simplifier, free_variables
from gsr.plan.grounding.static_join import StaticJoin, relation, static_join
from gsr.plan.task import Task

__all__ = [
    "GroundingTables",
    "GroundingTimeout",
    "ground_task",
    "grounding_tables",
    "schema_bindings",
]


class GroundingTimeout(GSRError):
    """Grounding did not finish before its deadline (``ground_task(..., deadline=...)``)."""


_CHECK_EVERY = 4096  # bindings between two looks at the clock (a look costs ~50 ns)
_MISSING = object()


def _check(deadline: float | None) -> None:
    if deadline is not None and perf_counter() > deadline:
        raise GroundingTimeout("grounding did not finish within the time limit")


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
        key = (si, k, *map(binding.__getitem__, free))
        false = memo.get(key)
        if false is None:
            false = memo[key] = simplify(part, binding) is FALSE
        if false:
            return True
    return False


# Reached and initial atoms by (predicate, argument position, value): a join atom with a bound
# argument scans only the atoms with that value there (pick's ``(on ?o ?from)`` once ``?o`` is bound).
ArgIndex = dict[tuple[str, int, str], list[tuple[str, ...]]]


def _index_atom(
    index: dict[str, set[tuple[str, ...]]],
    by_arg: ArgIndex,
    predicate: str,
    args: tuple[str, ...],
    added: dict[str, list[tuple[str, ...]]] | None = None,
    joined: frozenset[str] | None = None,
) -> None:
    """Add a new atom ``(predicate, args)`` to the indexes (and, in order of arrival, to ``added``);
    to ``by_arg`` only when its predicate is in ``joined`` (when given): the join reads no other."""
    index.setdefault(predicate, set()).add(args)
    if added is not None:
        added.setdefault(predicate, []).append(args)
    if joined is not None and predicate not in joined:
        return
    for k, v in enumerate(args):
        key = (predicate, k, v)
        found = by_arg.get(key)
        if found is None:
            by_arg[key] = [args]
        else:
            found.append(args)


def schema_bindings(
    schema: Schema,
    index: dict[str, set[tuple[str, ...]]],
    objects: ObjectsByType,
    disjunction: tuple[Atom, ...] = (),
    by_arg: ArgIndex | None = None,
    delta: dict[str, list[tuple[str, ...]]] | None = None,
    deadline: float | None = None,
    extra: tuple[Atom, ...] = (),
) -> list[dict]:
    """All parameter bindings whose join atoms hold in the (relaxed) reached set, typed.

    With ``delta`` (the atoms reached since the last call, by predicate; no disjunction), only the
    bindings that use at least one of them are listed (semi-naive evaluation): each join atom in
    turn is matched against the new atoms only, the others against all reached atoms.

    With a ``disjunction`` of atoms (pick's ``(or (on ?o ?from) (in ?o ?from))``), only bindings
    under which one of its atoms holds are listed: each alternative is joined like a join atom
    instead of enumerating every object for the variables it binds and testing it afterwards.

    ``extra`` atoms are joined like join atoms (static relations in ``index``, see
    gsr.plan.grounding.static_join); they are never new in ``delta``.
    """
    params = schema.all_params
    # The objects each parameter may take (typed); None for a variable that is no parameter.
    allowed: dict[str, frozenset[str]] = {}
    for p in params:
        objects(p.types)
        allowed[p.name] = objects.sets[p.types]
    atoms = (*schema.join, *extra) if extra else schema.join
    out: list[dict] = []
    seen: set[tuple[str, ...]] = set()
    dedupe = bool(disjunction) or delta is not None
    names, nparams = [p.name for p in params], len(params)
    # Per atom: its arguments with whether each is a variable (looked at for every tuple).
    specs = {id(a): tuple((x, is_variable(x)) for x in a.args) for a in (*atoms, *disjunction)}

    def finish(binding: dict[str, str]) -> None:
        if not len(out) % _CHECK_EVERY:
            _check(deadline)
        # Bindings hold parameters only (matches binds no other variable), so a full one has them all.
        if len(binding) == nparams:  # the usual case: the join bound every parameter (a fresh dict per match)
            if dedupe:  # a binding may satisfy several alternatives / use several new atoms
                key = tuple(map(binding.__getitem__, names))
                if key in seen:
                    return
                seen.add(key)
            out.append(binding)
            return
        free = [p for p in params if p.name not in binding]
        for combo in itertools.product(*(objects(p.types) for p in free)):
            full = dict(binding)
            full.update(zip((p.name for p in free), combo, strict=True))
            if dedupe:
                key = tuple(full[p.name] for p in params)
                if key in seen:
                    continue
                seen.add(key)
            out.append(full)

    def matches(
        atom: Atom, binding: dict[str, str], tuples: Iterable[tuple[str, ...]] | None = None
    ) -> Iterator[dict[str, str]]:
        spec = specs[id(atom)]
        if tuples is None and by_arg is not None:  # the smallest bucket of a bound argument
            for k, (a, var) in enumerate(spec):
                v = binding.get(a) if var else a
                if v is not None:
                    found = by_arg.get((atom.predicate, k, v), ())
                    if tuples is None or len(found) < len(tuples):  # type: ignore[arg-type]
                        tuples = found
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

    def size(atom: Atom, binding: dict[str, str]) -> int:
        """How many reached tuples a join atom would scan under ``binding`` (join ordering)."""
        best = len(index.get(atom.predicate, ()))
        if by_arg is not None:
            for k, (a, var) in enumerate(specs[id(atom)]):
                v = binding.get(a) if var else a
                if v is not None:
                    n = len(by_arg.get((atom.predicate, k, v), ()))
                    if n < best:
                        best = n
        return best

    def rec(todo: tuple[Atom, ...], binding: dict[str, str]) -> None:
        if not todo:
            if not disjunction:
                finish(binding)
                return
            for alt in disjunction:
                for nb in matches(alt, binding):
                    finish(nb)
            return
        # Join ordering: the atom with the fewest candidate tuples under the current binding goes
        # next (tetris' L moves: the piece's position before the free cells next to it).
        k = 0
        if len(todo) > 1:
            sizes = [size(a, binding) for a in todo]
            k = sizes.index(min(sizes))
        rest = todo[:k] + todo[k + 1 :]
        for nb in matches(todo[k], binding):
            rec(rest, nb)

    if delta is None:
        rec(tuple(atoms), {})
        return out
    for k, atom in enumerate(atoms):
        new = delta.get(atom.predicate)
        if new:
            for nb in matches(atom, {}, new):
                rec(atoms[:k] + atoms[k + 1 :], nb)
    return out


def _disjunction(schema: Schema, alternatives: list[tuple[Formula, ...]]) -> tuple[Atom, ...]:
    """The first top-level disjunction of atoms each binding a variable the join atoms leave free."""
    bound = {a for atom in schema.join for a in atom.args if is_variable(a)}
    for alts in alternatives:
        if all(isinstance(q, Atom) and any(is_variable(a) and a not in bound for a in q.args) for q in alts):
            return alts  # type: ignore[return-value]
    return ()


# A precondition conjunct, its free variables if fewer than the action's (memo key), and its kind:
# the common shapes are grounded directly instead of through the Simplifier. A split disjunction
# (kind _SPLIT) is given as an OrSplit in place of its memo key.
Part = tuple[Formula, "tuple[str, ...] | OrSplit | None", int]
_GENERIC, _SKIP, _FLUENT, _NOT_FLUENT, _DISTINCT, _SPLIT = range(6)
# A disjunction over all the action's variables whose disjuncts mostly mention fewer of them (pick's
# ``(imply (in ?o ?from) (not (exists (?y) (on ?y ?from))))``): (its disjuncts over all variables,
# and per smaller set of variables the disjunction of those over it, with that set, sorted). Each
# such group is simplified once per value of its variables, and a true one makes the whole
# conjunct true before anything per binding is built.
OrSplit = tuple[tuple[Formula, ...], tuple[tuple[Formula, tuple[str, ...]], ...]]


def _disjuncts(formula: Formula) -> list[Formula]:
    """The disjuncts of a (nested) disjunction."""
    if isinstance(formula, Or):
        return [q for p in formula.parts for q in _disjuncts(p)]
    return [formula]


def or_split(part: Formula, params: set[str]) -> OrSplit | None:
    """The OrSplit of a disjunction over all of ``params``; None when no disjunct mentions fewer."""
    if not isinstance(part, Or):
        return None
    full: list[Formula] = []
    groups: dict[tuple[str, ...], list[Formula]] = {}
    for q in _disjuncts(part):
        free = free_variables(q)
        if free >= params:
            full.append(q)
        else:
            groups.setdefault(tuple(sorted(free)), []).append(q)
    if not groups:
        return None
    return tuple(full), tuple(
        (qs[0] if len(qs) == 1 else Or(tuple(qs)), names) for names, qs in sorted(groups.items())
    )


def _part_kind(part: Formula, join: bool, fluent: set[str]) -> int:
    """How ``general_variant`` grounds one conjunct (see Part)."""
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
    names = {p.name for p in schema.all_params}
    out: list[Part] = []
    for k, part in enumerate((*schema.join, *_conjuncts(schema.residual))):
        free = free_variables(part)
        memo = tuple(sorted(free)) if len(free) < len(names) and not isinstance(part, Atom) else None
        kind = _part_kind(part, k < len(schema.join), fluent)
        split = or_split(part, names) if memo is None and kind == _GENERIC else None
        out.append((part, split, _SPLIT) if split is not None else (part, memo, kind))
    return out


def _split_disjunction(
    key: tuple, split: OrSplit, binding: dict[str, str], simplify: Simplifier, memo: dict[tuple, Formula]
) -> Formula:
    """A split disjunction under ``binding`` (see OrSplit): its groups memoised, nested Ors flattened."""
    full, groups = split

    def parts():  # the groups (memoised per value of their variables), then the unsplit disjuncts
        for gi, (group, names) in enumerate(groups):
            gkey = (*key, gi, *map(binding.__getitem__, names))
            g = memo.get(gkey)
            if g is None:
                g = memo[gkey] = simplify(group, binding)
            yield g
        for q in full:
            yield simplify(q, binding)

    alts: list[Formula] = []
    for g in parts():  # lazily: a true part settles the disjunction before the rest is simplified
        if g is TRUE:
            return TRUE
        if g is not FALSE:
            if type(g) is Or:
                alts.extend(g.parts)  # type: ignore[union-attr]
            else:
                alts.append(g)
    if not alts:
        return FALSE
    return alts[0] if len(alts) == 1 else Or(tuple(alts))


def general_variant(
    schema: Schema,
    si: int,
    parts: list[Part],
    binding: dict[str, str],
    simplify: Simplifier,
    memo: dict[tuple, Formula],
    cores: FormulaCache,
) -> Variant | None:
    """Ground one action's precondition; None when it is statically false.

    Conjuncts over fewer variables than the action (``(imply (openable ?c) (open ?c))`` in
    place_in) are simplified once per value of their variables.
    """
    pos: list[AtomKey] = []
    neg: list[AtomKey] = []
    compound: list[Formula] = []
    core: list[Formula] = []  # the relaxed core of each compound conjunct (see relaxed_core)
    for k, (part, free, kind) in enumerate(parts):
        if kind == _FLUENT:
            pos.append((part.predicate, tuple(map(binding.get, part.args, part.args))))  # type: ignore[union-attr]
            continue
        if kind == _NOT_FLUENT:
            a = part.formula  # type: ignore[union-attr]
            neg.append((a.predicate, tuple(map(binding.get, a.args, a.args))))
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
        if kind == _SPLIT:
            g = _split_disjunction((si, k), free, binding, simplify, memo)  # type: ignore[arg-type]
        elif free is None:
            g = simplify(part, binding)
        else:
            key = (si, k, *map(binding.get, free, free))  # type: ignore[arg-type]
            g = memo.get(key)  # type: ignore[assignment]
            if g is None:
                g = memo[key] = simplify(part, binding)
        if g is FALSE:
            return None
        if g is not TRUE:
            shape = type(g)
            if shape is Atom:
                pos.append((g.predicate, g.args))  # type: ignore[union-attr]
            elif shape is Not and type(g.formula) is Atom:  # type: ignore[union-attr]
                neg.append((g.formula.predicate, g.formula.args))  # type: ignore[union-attr]
            else:
                compound.append(g)
                if shape is not Not:  # a negative literal is dropped (true) in the relaxation
                    c = relaxed_core(g, cores)
                    if c is not TRUE:
                        core.append(c)
    args = tuple([binding[p.name] for p in schema.params])
    return Variant(schema.name, args, binding, schema, tuple(pos), tuple(neg), tuple(compound), tuple(core))


def _general(
    schema: Schema,
    si: int,
    parts: list[Part],
    simplify: Simplifier,
    memo: dict[tuple, Formula],
    cores: FormulaCache,
):
    """The general path as a function of the binding alone."""

    def general(binding: dict[str, str]) -> Variant | None:
        return general_variant(schema, si, parts, binding, simplify, memo, cores)

    return general


# The compiled preconditions (gsr.plan.grounding.compiled) on or off (tests compare both paths).
COMPILED = os.environ.get("GSR_GROUND_COMPILED", "1") != "0"


@dataclass(frozen=True, slots=True)
class GroundingTables:
    """What grounding derives from a domain alone: normalised schemas and their per-schema tables."""

    schemas: list[Schema]
    fluent: set[str]
    groups: list[list[EffectGroup]]
    alternatives: list[list[tuple[Formula, ...]]]
    narrow: list[list[tuple[Formula, tuple[str, ...]]]]
    parts: list[list[Part]]
    disjunctions: list[tuple[Atom, ...]]  # joined while listing bindings (see schema_bindings)
    triggers: list[tuple[str, ...]]  # predicates whose growth can give a schema new bindings
    factories: list  # compiled preconditions (gsr.plan.grounding.compiled), one per schema
    fires: list  # compiled effects (gsr.plan.grounding.compiled_effects), one per schema
    # The narrow disjunctions (see ``narrow``) over static predicates only: the compiled path tests
    # these before building a binding's precondition (push's "parts of one thing" rules out most
    # of its bindings; memoised per value of their variables, like _ruled_out).
    static_narrow: list[list[tuple[Formula, tuple[str, ...]]]]
    # Those of them joined while listing (gsr.plan.grounding.static_join), per schema.
    static_joins: list[tuple[StaticJoin, ...]]
    # The predicates of every schema's join atoms and joined disjunction (what schema_bindings looks
    # up by argument); set once the static joins are known (their relations are joined too).
    joined: frozenset[str] = frozenset()


# The few most recent domains, by identity (load_builtin_domain hands out one cached object, so a
# run of plan() calls on one domain compiles its schemas once). The domain is kept in the entry so
# that its id stays valid; domains are treated as immutable, like the rest of gsr.pddl.model.
_COMPILED: list[tuple[Domain, GroundingTables]] = []
_COMPILED_MAX = 4


def grounding_tables(domain: Domain) -> GroundingTables:
    """The domain-only grounding tables of ``domain`` (memoised on its identity)."""
    for known, compiled in _COMPILED:
        if known is domain:
            return compiled
    # Derived-predicate rules ground like actions that add their head (no deletes, no cost); the
    # interning step turns them into the Task's axioms (see axiom_action).
    schemas = [
        case
        for a in (*domain.actions.values(), *map(axiom_action, domain.axioms))
        for case in split_cases(normalize_action(a))
    ]
    fluent = {e.literal.atom.predicate for s in schemas for e in s.effects}
    # Effect groups need only the fluent predicates (literal splitting, static guards).
    no_objects = Simplifier(ObjectsByType(domain, {}), fluent, ())
    compiled = GroundingTables(
        schemas,
        fluent,
        [effect_groups(s, no_objects) for s in schemas],
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
        [],
        [],
        [],
        [],
    )
    for s, alts in zip(schemas, compiled.alternatives, strict=True):
        disjunction = _disjunction(s, alts)
        if disjunction:
            alts.remove(disjunction)  # holds for every listed binding: no need to test it again
        compiled.disjunctions.append(disjunction)
        compiled.triggers.append(tuple(a.predicate for a in (*s.join, *disjunction)))
    kinds = (_GENERIC, _SKIP, _FLUENT, _NOT_FLUENT, _DISTINCT, _SPLIT)
    memo_tables: dict[tuple, int] = {}  # one numbering for all the schemas (shared tables)
    compiled.factories.extend(
        compile_schema(s, p, kinds, fluent, memo_tables) for s, p in zip(schemas, compiled.parts, strict=True)
    )
    compiled.fires.extend(compile_effects(s, g) for s, g in zip(schemas, compiled.groups, strict=True))
    compiled.static_narrow.extend(
        [(part, free) for part, free in parts if not any(a.predicate in fluent for a in atoms_of(part))]
        for parts in compiled.narrow
    )
    for si, parts in enumerate(compiled.static_narrow):
        joins = (static_join(part, free, f"#static-or:{si}:{k}") for k, (part, free) in enumerate(parts))
        compiled.static_joins.append(tuple(j for j in joins if j is not None))
    heads = {join[0].predicate for joins in compiled.static_joins for join in joins}
    joined = {a.predicate for s, d in zip(schemas, compiled.disjunctions, strict=True) for a in (*s.join, *d)}
    compiled = dataclasses.replace(compiled, joined=frozenset(joined | heads | {EQUALS}))
    _COMPILED.insert(0, (domain, compiled))
    del _COMPILED[_COMPILED_MAX:]
    return compiled


def ground_task(domain: Domain, problem: Problem, deadline: float | None = None) -> Task:
    """Ground a problem: only relaxed-reachable operators, static atoms compiled away.

    With ``deadline`` (a ``time.perf_counter()`` value), a grounding still running then raises
    GroundingTimeout: the clock is read every few thousand bindings, so a task whose grounding
    blows up (IPC labyrinth: ~10^5 operators from 8-parameter moves) cannot overrun a planner's
    time limit by more than a fraction of a second.
    """
    objects = ObjectsByType(domain, problem.all_objects(domain))
    compiled = grounding_tables(domain)
    schemas, fluent = compiled.schemas, compiled.fluent
    init = set(problem.init)
    simplify = Simplifier(objects, fluent, init)

    index: dict[str, set[tuple[str, ...]]] = {}
    by_arg: ArgIndex = {}
    added: dict[str, list[tuple[str, ...]]] = {}  # reached atoms by predicate, in order of arrival
    # Only join atoms look atoms up by argument (schema_bindings): the other predicates (cube_count,
    # has_color, next on the tabletop domain: ~2/5 of its atoms) are not indexed by argument.
    joined = compiled.joined
    for a in init:
        _index_atom(index, by_arg, a.predicate, a.args, added, joined)
    if any(atom.predicate == EQUALS for s in schemas for atom in s.join):
        # Equalities of split cases join against (o, o) for every object (never a task atom).
        for o in sorted(objects.objects):
            _index_atom(index, by_arg, EQUALS, (o, o))
    # Static disjunctions as relations over the initial atoms, joined like join atoms (static_join).
    extra: list[tuple[Atom, ...]] = []
    for joins in compiled.static_joins:
        heads = []
        for join in joins:
            rel = relation(join, index)
            if rel is not None:
                for tup in rel:
                    _index_atom(index, by_arg, join[0].predicate, tup)
                heads.append(join[0])
        extra.append(tuple(heads))
    groups, alternatives, narrow, parts = (
        compiled.groups,
        compiled.alternatives,
        compiled.narrow,
        compiled.parts,
    )
    disjunctions, triggers = compiled.disjunctions, compiled.triggers
    fires = compiled.fires if COMPILED else None
    # Disjunctions _ruled_out tests before a binding's precondition is built: all narrow ones on
    # the general path, the static ones on the compiled path (it evaluates the others itself).
    rule_out = narrow if not COMPILED else compiled.static_narrow
    narrow_memo: dict[tuple, bool] = {}
    part_memo: dict[tuple, Formula] = {}
    cores: FormulaCache = {}
    cache: dict[tuple, Variant | None] = {}
    fired: list[Variant] = []
    # Add effects of fired operators not reached yet: (positive condition atoms, atom key). Each
    # round only scans these, not every effect of every fired operator again.
    pending: list[tuple[tuple[AtomKey, ...], AtomKey]] = []
    reached_keys: set[AtomKey] = {(a.predicate, a.args) for a in init}
    deferred: list[Deferred] = []
    effect_memo: EffectMemo = {}
    join_sizes: list[tuple[int, ...] | None] = [None] * len(schemas)
    # Each schema's compiled precondition, handing a binding it cannot hold to general_variant.
    shared: dict = {}
    variant_of = [
        bind(factory, simplify, _general(schema, si, parts[si], simplify, part_memo, cores), shared)
        if COMPILED and factory is not None
        else _general(schema, si, parts[si], simplify, part_memo, cores)
        for si, (schema, factory) in enumerate(zip(schemas, compiled.factories, strict=True))
    ]
    # Bindings that may fire later, as (key, binding): a built action waiting for a positive
    # precondition atom is kept under that atom (``watch``) and looked at again once it is
    # reached (``retry``); the others (a disjunction or alternative not reached yet) every round.
    slow: list[list[tuple[tuple, dict[str, str]]]] = [[] for _ in schemas]
    retry: list[list[tuple[tuple, dict[str, str]]]] = [[] for _ in schemas]
    watch: dict[AtomKey, list[tuple[int, tuple, dict[str, str]]]] = {}
    watched: set[tuple] = set()
    all_names = [[p.name for p in schema.all_params] for schema in schemas]
    changed = True
    while changed:
        changed = False
        for si, schema in enumerate(schemas):
            names = all_names[si]
            # Bindings depend only on the join predicates' atoms: while those did not grow, only
            # the bindings that have not fired yet (and may now) are looked at again.
            sizes = tuple([len(index.get(p, ())) for p in triggers[si]])
            old = join_sizes[si]
            candidates = slow[si] + retry[si]
            retry[si] = []
            if sizes != old:
                join_sizes[si] = sizes
                if old is None or disjunctions[si] or not schema.join:
                    new = schema_bindings(
                        schema, index, objects, disjunctions[si], by_arg, None, deadline, extra[si]
                    )
                else:
                    # Semi-naive: only the bindings using an atom reached since the last listing
                    # are new; the others are fired already or waiting.
                    delta = {p: added.get(p, [])[n:] for p, n in zip(triggers[si], old, strict=True)}
                    new = schema_bindings(schema, index, objects, (), by_arg, delta, deadline, extra[si])
                for b in new:
                    key = (si, *map(b.__getitem__, names))
                    if key not in watched:
                        candidates.append((key, b))
            slow[si] = still = []
            listed: set[tuple] = set()
            for count, (key, binding) in enumerate(candidates):
                if not count % _CHECK_EVERY:
                    _check(deadline)
                if key in listed:
                    continue
                listed.add(key)
                v = cache.get(key, _MISSING)
                if v is _MISSING:
                    # (A compiled precondition evaluates the non-static narrow ones itself, memoised.)
                    if rule_out[si] and _ruled_out(si, rule_out[si], binding, simplify, narrow_memo):
                        cache[key] = None
                        continue
                    if alternatives[si] and not _any_reached(alternatives[si], binding, reached_keys):
                        still.append((key, binding))
                        continue
                    v = cache[key] = variant_of[si](binding)
                if v is None or v.fired:
                    continue
                if not reached_keys.issuperset(v.pos):
                    missing = next(k for k in v.pos if k not in reached_keys)
                    watch.setdefault(missing, []).append((si, key, binding))
                    watched.add(key)
                elif (v.core and not all(relaxed(c, reached_keys) for c in v.core)) or (
                    (v.choices or v.pieces) and not v.choices_hold(reached_keys)
                ):
                    still.append((key, binding))
                else:
                    v.fired = True
                    fired.append(v)
                    if fires is not None:  # compiled: the same blocks and queued adds, in order
                        fires[si](v, simplify, reached_keys, deferred, effect_memo, pending)
                    else:
                        ground_effects(v, groups[si], simplify, reached_keys, deferred, effect_memo)
                        new_adds(v.effects, reached_keys, pending)
        # Deferred effect groups whose binding-level condition is now reached get grounded.
        blocked = []
        for v, group, binding, base in deferred:
            if any(pos and k not in reached_keys for k, pos in base):
                blocked.append((v, group, binding, base))
                continue
            start = len(v.effects)
            ground_group(group, binding, base, simplify, v.effects, effect_memo)
            new_adds(v.effects[start:], reached_keys, pending)
        deferred = blocked
        # Fire the add effects of reached operators whose (positive) conditions are reached.
        waiting = []
        for cond, key in pending:
            if key in reached_keys:
                continue
            if reached_keys.issuperset(cond):
                reached_keys.add(key)
                _index_atom(index, by_arg, key[0], key[1], added, joined)
                changed = True
                for si, bkey, binding in watch.pop(key, ()):
                    watched.discard(bkey)
                    retry[si].append((bkey, binding))
            else:
                waiting.append((cond, key))
        pending = waiting
    _check(deadline)
    return intern_task(domain, problem, fired, reached_keys, fluent, simplify)
