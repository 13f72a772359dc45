"""Interning: the fired ground actions of the reachability fixpoint into a Task over atom ids."""

from __future__ import annotations

from bisect import bisect_left
from operator import invert

from gsr.errors import GSRError
from gsr.pddl.axioms import strata
from gsr.pddl.model import Action, And, Atom, Axiom, Domain, Formula, Increase, Literal, Problem
from gsr.pddl.walk import nnf, to_dnf
from gsr.plan.grounding.effects import EMPTY, EffectPart, KeyConjunction, Variant
from gsr.plan.grounding.precondition import AtomKey, FormulaCache, IdConjunction, expand_dnf, fast_dnf, id_dnf
from gsr.plan.grounding.simplify import ObjectsByType, Simplifier
from gsr.plan.task import GroundOp, Task

AXIOM_PREFIX = "axiom:"  # no PDDL action name has a colon


def axiom_action(axiom: Axiom) -> Action:
    """A derived-predicate rule as an action that adds its head: grounded by the same relaxed
    reachability fixpoint (negated derived atoms in its body are relaxed away like every negative
    literal), then split off into Task.axioms by the interning step."""
    return Action(f"{AXIOM_PREFIX}{axiom.name}", axiom.params, axiom.body, Literal(axiom.head))


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


def _condition_ids(
    cond: KeyConjunction, ids: dict[AtomKey, int]
) -> tuple[tuple[int, ...], tuple[int, ...]] | tuple[()]:
    """(positive ids, negative ids) of a condition, sorted; () when it needs an unreached atom."""
    pos_ids: list[int] = []
    neg_ids: list[int] = []
    for k, pos in cond:
        i = ids.get(k)
        if pos:
            if i is None:
                return ()
            pos_ids.append(i)
        elif i is not None:
            neg_ids.append(i)
    return (
        tuple(sorted(pos_ids)) if len(pos_ids) > 1 else tuple(pos_ids),
        tuple(sorted(neg_ids)) if len(neg_ids) > 1 else tuple(neg_ids),
    )


# An effect part over atom ids: (condition positive ids, condition negative ids, add ids, delete
# ids), all sorted; with the set of condition ids of all parts of its list.
_PartIds = tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...], tuple[int, ...]]


def _parts_ids(parts: list[EffectPart], key_ids: dict[AtomKey, int]) -> tuple[list[_PartIds], frozenset[int]]:
    """Effect parts over atom ids; parts needing, or changing only, never-reached atoms dropped."""
    out: list[_PartIds] = []
    for inner, ground in parts:
        if len(inner) == 1:  # the common one-literal condition (cube counting's count), inline
            ((k, pos),) = inner
            i = key_ids.get(k)
            if pos:
                if i is None:
                    continue
                r = ((i,), ())
            else:
                r = ((), (i,) if i is not None else ())
        else:
            r = _condition_ids(inner, key_ids) if inner else ((), ())
            if not r:
                continue
        adds = tuple([i for a, is_del in ground if not is_del and (i := key_ids.get(a)) is not None])
        dels = tuple([i for a, is_del in ground if is_del and (i := key_ids.get(a)) is not None])
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


def _choice_ids(
    alternatives: tuple[tuple[tuple[AtomKey, ...], tuple[AtomKey, ...]], ...],
    key_ids: dict[AtomKey, int],
    cache: FormulaCache,
) -> list[IdConjunction] | None:
    """A choice's alternatives over atom ids: one needing an unreached atom dropped, an unreached
    atom's negation dropped from its alternative; None when an alternative is left empty (the
    choice holds).

    Each alternative is converted once per object (``cache``, by id; the entry keeps it alive): a
    choice is built per binding, but most of its alternatives come from memoised conjuncts shared
    by every binding with the same values (pick's ``(forall (?y) (not (on ?y ?from)))`` per ?from).
    """
    out: list[IdConjunction] = []
    for alt in alternatives:
        hit = cache.get(id(alt))
        if hit is None:
            hit = cache[id(alt)] = (alt, _alternative_ids(alt, key_ids))
        lits = hit[1]
        if lits is None:
            continue  # needs an atom never reached
        if not lits:
            return None
        out.append(lits)  # type: ignore[arg-type]
    return out


def _alternative_ids(
    alt: tuple[tuple[AtomKey, ...], tuple[AtomKey, ...]], key_ids: dict[AtomKey, int]
) -> IdConjunction | None:
    """One alternative of a choice over atom ids (see _choice_ids); None when it needs an atom
    never reached, empty when it holds."""
    pos, neg = alt
    lits: list[int] = []
    for k in pos:
        i = key_ids.get(k)
        if i is None:
            return None
        lits.append(i)
    for k in neg:
        i = key_ids.get(k)
        if i is not None:
            lits.append(~i)
    return frozenset(lits)


def _piece_ids(
    piece: tuple, key_ids: dict[AtomKey, int], cache: FormulaCache
) -> tuple[list[int], list[list[IdConjunction]]] | None:
    """A memoised key-form conjunct's negative literals and choices over atom ids (its positive
    keys are in the variant's own); None when one of its choices cannot hold."""
    lits = [~i for k in piece[1] if (i := key_ids.get(k)) is not None]
    choices: list[list[IdConjunction]] = []
    for alternatives, _relax in piece[2]:
        alts = _choice_ids(alternatives, key_ids, cache)
        if alts is None:
            continue
        if not alts:
            return None
        if len(alts) == 1:  # a choice left with one alternative is its literals (see expand_dnf)
            lits += alts[0]
        else:
            choices.append(alts)
    return lits, choices


def _signed(disjunct: IdConjunction) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(positive ids, negated ids) of a conjunction of id literals, each sorted ascending: one
    sort, the negative literals (``~i``, below 0) first in descending order of their ids."""
    lits = sorted(disjunct)
    k = bisect_left(lits, 0)
    if not k:
        return tuple(lits), ()
    return tuple(lits[k:]), tuple(map(invert, reversed(lits[:k])))


def precondition_dnf(
    v: Variant, key_ids: dict[AtomKey, int], scanned: FormulaCache
) -> list[IdConjunction] | None:
    """``fast_dnf(v.pre)`` without building ``v.pre``: the fluent literals go to atom ids by key,
    the compound conjuncts through fast_dnf, and each of their disjuncts takes the literals (those
    contradicting one drop it; a disjunct that comes to contain another is dropped). None when
    fast_dnf cannot take the compound conjuncts (the general path then takes ``v.pre``)."""
    lits = list(map(key_ids.get, v.pos))
    if None in lits:
        return []  # needs an atom never reached
    if v.neg:  # a never-reached atom's negation holds: dropped
        lits += [~i for i in map(key_ids.get, v.neg) if i is not None]
    if v.choices or v.pieces:  # the compiled path (no compound conjuncts)
        choices: list[list[IdConjunction]] = []
        for piece in v.pieces:  # shared memoised conjuncts: converted once each
            hit = scanned.get(id(piece))
            if hit is None:
                hit = scanned[id(piece)] = (piece, _piece_ids(piece, key_ids, scanned))
            found = hit[1]
            if found is None:
                return []
            lits += found[0]  # type: ignore[index]
            choices += found[1]  # type: ignore[index]
        for choice in v.choices:  # built per binding (never shared): converted here
            alts = _choice_ids(choice[0], key_ids, scanned)
            if alts is None:
                continue  # holds: an alternative needs nothing (its unreached atoms are false)
            if not alts:
                return []
            if len(alts) == 1:  # one alternative left: its literals (see expand_dnf)
                lits += alts[0]
            else:
                choices.append(alts)
        return expand_dnf(lits, choices)
    base = frozenset(lits)
    if any(~x in base for x in base):
        return []
    if not v.compound:
        return [base]
    found = fast_dnf(And(v.compound), key_ids, scanned)
    if found is None or not base:
        return found
    merged = sorted({d | base for d in found if not any(~x in base for x in d)}, key=len)
    kept: list[IdConjunction] = []
    for d in merged:
        if not any(k <= d for k in kept):
            kept.append(d)
    return kept


def intern_task(
    domain: Domain,
    problem: Problem,
    fired: list[Variant],
    reached: set[AtomKey],
    fluent: set[str],
    simplify: Simplifier | None = None,
) -> Task:
    """The Task of the fired actions over the reached fluent atoms (``reached``: their
    ``(predicate, args)`` keys, the initial ones included; ``simplify``: the grounding's, reused for
    the goal)."""
    keys = sorted([k for k in reached if k[0] in fluent])  # by (predicate, args), as the atoms
    key_ids = {k: i for i, k in enumerate(keys)}
    initial = {(a.predicate, a.args): a for a in problem.init}  # the initial atoms' own objects
    atoms = [a if (a := initial.get(k)) is not None else Atom(*k) for k in keys]
    reached_atoms: set[Atom] | None = None  # the general path's prune (built when needed)
    # The operators by their fields (name, args, pre, neg, add, delete, cond, cost): tuples hash and
    # compare in C, so duplicates are dropped and the order is taken without a GroundOp each.
    ops: set[tuple] = set()
    # Condition parts over atom ids, by object (parts are shared by many effects and actions;
    # every part is referenced from the fired actions, so ids stay unique).
    converted: dict[int, tuple[tuple[int, ...], tuple[int, ...]] | tuple[()]] = {}
    scanned: FormulaCache = {}  # DNF parts of the shared precondition conjuncts
    parts_ids: dict[int, tuple[list[EffectPart], list[_PartIds], frozenset[int]]] = {}  # by list
    filtered: dict[tuple, tuple[list[_PartIds], list[_PartIds]]] = {}  # see _filtered_parts
    cond_tables: dict[tuple, tuple] = {}  # see _cond_table
    unit = problem.metric is None  # every action costs 1 (see _cost)
    for v in fired:
        disjuncts = precondition_dnf(v, key_ids, scanned)
        if disjuncts is None:
            if reached_atoms is None:
                reached_atoms = {Atom(*k) for k in reached}
            disjuncts = id_dnf(v.pre, reached_atoms, key_ids)
        if not disjuncts:
            continue
        # The variant's effect blocks over atom ids; effects on never-reached atoms, or needing
        # one, never matter. An unconditional block (its own one-part list, see ground_group) goes
        # straight into plain adds and deletes.
        blocks = []
        plain_add: list[int] = []
        plain_del: list[int] = []
        for base, parts in v.effects or ():
            if base is EMPTY and len(parts) == 1 and parts[0][0] is EMPTY:
                for a, is_del in parts[0][1]:
                    i = key_ids.get(a)
                    if i is not None:
                        (plain_del if is_del else plain_add).append(i)
                continue
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
        cost = 1.0 if unit else _cost(v.schema.costs, v.binding, problem)
        if not blocks:  # no conditional effect: the same adds and deletes for every disjunct
            add_ids = set(plain_add)
            adds, dels = tuple(sorted(add_ids)), tuple(sorted(set(plain_del) - add_ids))
            for disjunct in disjuncts:
                pre, neg = _signed(disjunct)
                ops.add((v.name, v.args, pre, neg, adds, dels, (), cost))
            continue
        for disjunct in disjuncts:
            pre, neg = _signed(disjunct)
            pre_set, neg_set = set(pre), set(neg)
            add: set[int] = set(plain_add)
            dele: set[int] = set(plain_del)
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
            ops.add((v.name, v.args, pre, neg, tuple(sorted(add)), tuple(sorted(dele - add)), conds, cost))
    ordered = [
        GroundOp(name, args, cost, pre, neg, add, delete, cond)
        for name, args, pre, neg, add, delete, cond, cost in sorted(ops)
    ]
    init = 0
    for a in problem.init:
        i = key_ids.get((a.predicate, a.args))
        if i is not None:
            init |= 1 << i
    goals = _goal_ids(domain, problem, problem.goal, key_ids, fluent, simplify)
    if not domain.axioms:
        return Task(atoms, ordered, init, goals)
    level = {pred: k for k, preds in enumerate(strata(domain)) for pred in preds}
    axioms = [o for o in ordered if o.name.startswith(AXIOM_PREFIX) and o.add]
    actions = [o for o in ordered if not o.name.startswith(AXIOM_PREFIX)]
    return Task(
        atoms,
        actions,
        init,
        goals,
        axioms=axioms,
        axiom_strata=[level[o.name[len(AXIOM_PREFIX) :]] for o in axioms],
    )


def ground_goal(
    domain: Domain,
    problem: Problem,
    goal: Formula,
    ids: dict[Atom, int],
    fluent: set[str],
    simplify: Simplifier | None = None,
) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """The goal as a DNF over atom ids; disjuncts needing unreachable atoms are dropped.

    ``simplify``: a Simplifier over this problem's objects, ``fluent`` and initial state (the
    grounding's, with its memoised quantifiers); a new one when None.
    """
    key_ids = {(a.predicate, a.args): i for a, i in ids.items()}
    return _goal_ids(domain, problem, goal, key_ids, fluent, simplify)


def _goal_ids(
    domain: Domain,
    problem: Problem,
    goal: Formula,
    key_ids: dict[AtomKey, int],
    fluent: set[str],
    simplify: Simplifier | None = None,
) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """``ground_goal`` with the atom ids by ``(predicate, args)`` key."""
    if simplify is None:
        simplify = Simplifier(ObjectsByType(domain, problem.all_objects(domain)), fluent, problem.init)
    out = []
    for conj in to_dnf(simplify(nnf(goal), {})):
        keyed = [((a.predicate, a.args), pos) for a, pos in conj]
        if any(pos and k not in key_ids for k, pos in keyed):
            continue
        pos_ids = tuple(sorted(key_ids[k] for k, pos in keyed if pos))
        neg_ids = tuple(sorted(key_ids[k] for k, pos in keyed if not pos and k in key_ids))
        out.append((pos_ids, neg_ids))
    return out
