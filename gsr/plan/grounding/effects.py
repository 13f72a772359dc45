"""Effect grounding: a schema's effect groups, a fired action's ground effect blocks, and the add
effects they queue for the reachability fixpoint (see gsr.plan.grounding.fixpoint)."""

from __future__ import annotations

from dataclasses import dataclass

from gsr.pddl.model import Atom, Formula, Not, TypedVar, is_variable
from gsr.pddl.walk import to_dnf
from gsr.plan.grounding.normalize import Schema
from gsr.plan.grounding.precondition import AtomKey
from gsr.plan.grounding.simplify import Simplifier

# Ground effects come in blocks (base, parts), each part (inner, atoms): every (atom, is_delete) of
# a part takes effect under the union of base and inner. The parts list of a memoised effect group
# is shared by every action with the same values of the variables it mentions (pick's cube counting
# by ?from), so its atoms are grounded, and later interned, once for all of them.
# Effect atoms are (predicate, args) keys (AtomKey), not Atom objects: they are hashed a few times
# each (reached test, interning) and tuples hash and compare in C; the few that get reached become
# Atoms then. Look-ups of Atoms go through their keys for the same reason. The conditions (base and
# inner) are sets of key literals too (KeyConjunction), never Atoms: an Atom hashes through a Python
# __hash__ each time a set of them is built or probed.
KeyConjunction = frozenset[tuple[AtomKey, bool]]
EffectPart = tuple[KeyConjunction, tuple[tuple[AtomKey, bool], ...]]
EffectBlock = tuple[KeyConjunction, list[EffectPart]]
EffectMemo = dict[tuple, tuple[list[EffectPart], frozenset[AtomKey]]]


@dataclass(slots=True)
class Variant:
    """A ground action: its simplified precondition; effects are grounded once it fires.

    The precondition is the conjunction of its fluent literals, kept as (predicate, args) keys
    (no Atom is built for them: the reachability test and the interning look them up by key), and
    of its other simplified conjuncts (``compound``: disjunctions, instantiated quantifiers; the
    memoised ones are objects shared by many actions). ``pre`` gives it as one formula.
    """

    name: str
    args: tuple[str, ...]
    binding: dict[str, str]
    schema: Schema
    pos: tuple[AtomKey, ...]  # positive fluent literals
    neg: tuple[AtomKey, ...]  # negative fluent literals
    compound: tuple[Formula, ...]
    core: tuple[Formula, ...]  # what the delete relaxation tests of ``compound`` (see relaxed_core)
    effects: list[EffectBlock] | None = None
    fired: bool = False
    # Disjunctive conjuncts in key form (the compiled path, gsr.plan.grounding.compiled): per choice,
    # (its alternatives as (positive keys, negative keys), the positive keys of each alternative
    # or None when one has none: what the delete relaxation tests).
    choices: tuple = ()
    # Memoised conjuncts in key form (gsr.plan.grounding.compiled.KeyCnf), shared by many actions;
    # their positive keys are in ``pos`` too.
    pieces: tuple = ()

    @property
    def pre(self) -> Formula:
        """The simplified precondition as one formula (TRUE when it has no conjunct)."""
        parts: list[Formula] = [Atom(p, args) for p, args in self.pos]
        parts += [Not(Atom(p, args)) for p, args in self.neg]
        parts += [Not(Atom(p, args)) for piece in self.pieces for p, args in piece[1]]
        for alts, _relax in (*self.choices, *(c for piece in self.pieces for c in piece[2])):
            parts.append(Simplifier.combine(False, [_key_conj(p, n) for p, n in alts]))
        return Simplifier.combine(True, [*parts, *self.compound])

    def choices_hold(self, reached: set[AtomKey]) -> bool:
        """Whether every choice has an alternative whose positive keys are all reached."""
        for _alts, relax in self.choices:
            if relax is not None and not any(reached.issuperset(p) for p in relax):
                return False
        for piece in self.pieces:
            for relax in piece[3]:
                if not any(reached.issuperset(p) for p in relax):
                    return False
        return True


def _key_conj(pos: tuple[AtomKey, ...], neg: tuple[AtomKey, ...]) -> Formula:
    """A conjunction of key literals as a formula."""
    parts: list[Formula] = [Atom(p, args) for p, args in pos]
    parts += [Not(Atom(p, args)) for p, args in neg]
    return Simplifier.combine(True, parts)


EMPTY: KeyConjunction = frozenset()


Literals = tuple[tuple[Atom, bool], ...]
# (params, condition, guards, (outer, inner) literals or None, effect atoms with is_delete,
# action variables the per-instance part mentions)
EffectGroup = tuple[
    tuple[TypedVar, ...],
    Formula,
    tuple[Atom, ...],
    tuple[Literals, Literals] | None,
    Literals,
    tuple[str, ...],
]


def effect_groups(schema: Schema, simplify: Simplifier) -> list[EffectGroup]:
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
    out: list[EffectGroup] = []
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
        # Action variables the per-instance part mentions: its memo key (see ground_group).
        # Guards without effect variables are checked once per binding, in base/instances.
        names = {p.name for p in params}
        atoms = [g for g in guards if names.intersection(g.args)]
        atoms += [a for a, _ in split[1]] if split else []
        atoms += [a for a, _ in lits]
        used = tuple(sorted({x for a in atoms for x in a.args if is_variable(x) and x not in names}))
        out.append((params, cond, guards, split, tuple(lits), used))
    return out


Deferred = tuple[Variant, EffectGroup, dict[str, str], KeyConjunction]


def ground_effects(
    v: Variant,
    groups: list[EffectGroup],
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
        if unconditional(group):
            v.effects.append(_unconditional(group[4], v.binding))
        else:
            group_effects(v, group, simplify, reached, deferred, memo)


def unconditional(group: EffectGroup) -> bool:
    """Whether an effect group has neither effect variables nor a condition (one block per action)."""
    return group[3] == ((), ()) and not group[0]


def group_effects(
    v: Variant,
    group: EffectGroup,
    simplify: Simplifier,
    reached: set[AtomKey],
    deferred: list[Deferred],
    memo: EffectMemo,
) -> None:
    """Ground one (not unconditional) effect group of a fired action into ``v.effects``, or defer it
    (see ground_effects)."""
    split = group[3]
    base = None
    if split is not None:
        base = simplify.ground_literal_keys(split[0], v.binding)
        if base is None:
            return  # the condition is false whatever the effect variables are
        if any(pos and k not in reached for k, pos in base):
            deferred.append((v, group, v.binding, base))
            return
    ground_group(group, v.binding, base, simplify, v.effects, memo)  # type: ignore[arg-type]


def ground_group(
    group: EffectGroup,
    binding: dict[str, str],
    base: KeyConjunction | None,
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
        effects.append(_unconditional(lits, binding))
        return
    if split is not None and base is not None and memo is not None:
        key = (id(group), *map(binding.get, group[5], group[5]))
        entry = memo.get(key)
        if entry is None:
            parts: list[EffectPart] = []
            for b in effect_instances(group, binding, simplify, memo):
                inner = simplify.ground_literal_keys(split[1], b) if split[1] else frozenset()
                if inner is None:
                    continue
                ground = tuple(
                    [
                        ((atom.predicate, tuple(map(b.get, atom.args, atom.args))), is_del)
                        for atom, is_del in lits
                    ]
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
            conj = simplify.ground_literal_keys(split[1], b) if split[1] else base
            if conj is None:
                continue
            if conj is not base:
                if any((a, not pos) in base for a, pos in conj):
                    continue
                conj = base | conj
            conjs: list[KeyConjunction] = [conj]
        else:
            conjs = [
                frozenset([((a.predicate, a.args), pos) for a, pos in c])
                for c in to_dnf(simplify(condition, b))
            ]
        ground = tuple(
            ((atom.predicate, tuple(map(b.get, atom.args, atom.args))), is_del) for atom, is_del in lits
        )
        own.extend((conj, ground) for conj in conjs)
    if own:
        effects.append((EMPTY, own))


def effect_instances(
    group: EffectGroup, binding: dict[str, str], simplify: Simplifier, memo: EffectMemo
) -> list[dict[str, str]]:
    """``simplify.instances`` of a group's effect variables, the join over its static guards done
    once per value of the action variables the guards mention (memoised beside the group's parts:
    pick's cube counting ``(next ?n ?m)`` is joined once per task, not once per container)."""
    params, guards = group[0], group[2]
    if not params:
        return [binding]
    names = tuple(p.name for p in params)
    outer = sorted({a for g in guards for a in g.args if is_variable(a) and a not in names})
    key = ("instances", id(group), *(binding.get(a, a) for a in outer))
    values = memo.get(key)
    if values is None:
        found = [tuple(b[n] for n in names) for b in simplify.instances(params, guards, binding)]
        memo[key] = values = (found, frozenset())  # type: ignore[assignment]
    out = []
    for vals in values[0]:  # type: ignore[union-attr]
        full = dict(binding)
        full.update(zip(names, vals, strict=True))  # type: ignore[arg-type]
        out.append(full)
    return out


def _unconditional(lits: Literals, binding: dict[str, str]) -> EffectBlock:
    """The block of an unconditional effect group: its own one-part list (never worth memoising:
    the atoms mention the action's variables)."""
    ground = tuple([((a.predicate, tuple(map(binding.get, a.args, a.args))), d) for a, d in lits])
    return (EMPTY, [(EMPTY, ground)])


def new_adds(
    blocks: list[EffectBlock],
    reached: set[AtomKey],
    pending: list[tuple[tuple[AtomKey, ...], AtomKey]],
    memo: EffectMemo | None = None,
) -> None:
    """Queue the add effects not reached yet with their positive condition atoms (see ground_task).

    With ``memo``, each parts list's adds and the positive condition keys of their parts are listed
    once (a memoised list is shared by many actions: pick's cube counting by container)."""
    for base, parts in blocks:
        outer: tuple[AtomKey, ...] | None = None
        if memo is None:
            adds = _adds(parts)
        else:
            hit = memo.get(("adds", id(parts)))
            if hit is None:  # the entry keeps the list alive: its id stays its own
                hit = memo[("adds", id(parts))] = (parts, _adds(parts))  # type: ignore[assignment]
            adds = hit[1]  # type: ignore[assignment]
        for inner, atom in adds:
            if atom not in reached:
                if outer is None:
                    outer = tuple([k for k, pos in base if pos])
                pending.append((outer + inner, atom))


def _adds(parts: list[EffectPart]) -> list[tuple[tuple[AtomKey, ...], AtomKey]]:
    """The add effects of a parts list, in order, each with its part's positive condition keys."""
    out = []
    for inner, ground in parts:
        keys: tuple[AtomKey, ...] | None = None
        for atom, is_del in ground:
            if not is_del:
                if keys is None:
                    keys = tuple([k for k, pos in inner if pos])
                out.append((keys, atom))
    return out
