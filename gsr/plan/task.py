"""The ground planning task: interned atoms, ground operators and bitset masks.

A state is a Python ``int`` used as a bitset over interned fluent atoms: hashing, equality,
applicability (``s & pre == pre``) and progression (``s & ~del | add``) are single big-int
operations, measured faster than frozensets of ints for every domain in the benchmark.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from gsr.pddl.model import Atom
from gsr.step import Plan, Step

Ids = tuple[int, ...]
CondEffect = tuple[Ids, Ids, Ids, Ids]  # (condition pos, condition neg, add, delete)


# Not ``frozen``: a frozen dataclass's ``__init__`` sets each field through ``object.__setattr__``,
# ~5x the cost of a plain one (3.4 against 0.6 us; interning builds ~140 per tabletop task).
# Treat it as immutable all the same: the Task's masks are computed from its fields, and it
# hashes and compares by them as a frozen one does.
@dataclass(slots=True, unsafe_hash=True)
class GroundOp:
    """A ground operator (one DNF variant of a ground action) over atom ids."""

    name: str
    args: tuple[str, ...]
    cost: float
    pre: Ids
    neg: Ids
    add: Ids
    delete: Ids
    cond: tuple[CondEffect, ...] = ()

    def __str__(self) -> str:
        return f"({' '.join((self.name, *self.args))})"


def mask(ids: Ids) -> int:
    """The bitset with the given atom ids set."""
    m = 0
    for i in ids:
        m |= 1 << i
    return m


def bits(state: int) -> list[int]:
    """The atom ids set in a bitset, ascending."""
    if state.bit_count() > 48:  # dense: numpy unpacks the bytes (~5x faster at a few hundred bits)
        import numpy as np

        raw = np.frombuffer(state.to_bytes((state.bit_length() + 7) // 8, "little"), np.uint8)
        return np.flatnonzero(np.unpackbits(raw, bitorder="little")).tolist()
    out = []
    while state:
        low = state & -state
        out.append(low.bit_length() - 1)
        state ^= low
    return out


@dataclass(slots=True)
class Task:
    """A grounded task with precomputed masks and a successor index.

    ``axioms`` are the ground derived-predicate rules (a GroundOp whose ``add`` is its head atom;
    ``pre``/``neg`` its body) with ``axiom_strata`` their head's stratum. Derived atoms are bits of
    the state like the others, but always recomputed from the basic ones (``close``): the initial
    state and every successor are closed.
    """

    atoms: list[Atom]
    ops: list[GroundOp]
    init: int
    goals: list[tuple[Ids, Ids]]  # DNF over (positive ids, negative ids); empty list: unreachable goal
    has_cond: bool = False
    has_neg: bool = False
    unit_cost: bool = True
    pre_mask: list[int] = field(default_factory=list)
    neg_mask: list[int] = field(default_factory=list)
    add_mask: list[int] = field(default_factory=list)
    del_mask: list[int] = field(default_factory=list)
    cond_mask: list[tuple[tuple[int, int, int, int], ...]] = field(default_factory=list)
    goal_masks: list[tuple[int, int]] = field(default_factory=list)
    by_fact: list[list[int]] = field(default_factory=list)  # ops indexed by one precondition fact
    always: list[int] = field(default_factory=list)  # ops without positive precondition
    index_mask: int = 0  # facts with a non-empty by_fact bucket
    axioms: list[GroundOp] = field(default_factory=list)
    axiom_strata: list[int] = field(default_factory=list)
    derived_mask: int = 0
    # Per stratum: (axioms as (other-precondition mask, negative mask, head bit, head id, number of
    # same-stratum precondition atoms), same-stratum atom id -> axioms waiting for it).
    _layers: list[tuple[list[tuple[int, int, int, int, int]], dict[int, list[int]]]] = field(
        default_factory=list
    )

    def __post_init__(self) -> None:
        self._build_axioms()
        # ``mask`` inlined: one pass, no call per mask (4 per operator; ~1/3 of this loop's time).
        pre_mask: list[int] = []
        neg_mask: list[int] = []
        add_mask: list[int] = []
        del_mask: list[int] = []
        for o in self.ops:
            m = 0
            for i in o.pre:
                m |= 1 << i
            pre_mask.append(m)
            m = 0
            for i in o.neg:
                m |= 1 << i
            neg_mask.append(m)
            m = 0
            for i in o.add:
                m |= 1 << i
            add_mask.append(m)
            m = 0
            for i in o.delete:
                m |= 1 << i
            del_mask.append(m)
        self.pre_mask, self.neg_mask, self.add_mask, self.del_mask = pre_mask, neg_mask, add_mask, del_mask
        # Conditional effects repeat across operators (the cube-counting groups of every pick and
        # place): each distinct one is converted once.
        # Grounding hands many operators the very same cond tuple: converted once per object.
        cond_masks: dict[CondEffect, tuple[int, int, int, int]] = {}
        by_tuple: dict[int, tuple[tuple[int, int, int, int], ...]] = {}
        self.cond_mask = []
        for o in self.ops:
            found = by_tuple.get(id(o.cond))
            if found is None:
                for ce in o.cond:
                    if ce not in cond_masks:
                        p, n, a, d = ce
                        cond_masks[ce] = (mask(p), mask(n), mask(a), mask(d))
                found = by_tuple[id(o.cond)] = tuple(map(cond_masks.__getitem__, o.cond))
            self.cond_mask.append(found)
        self.goal_masks = [(mask(p), mask(n)) for p, n in self.goals]
        self.has_cond = any(o.cond for o in self.ops)
        self.has_neg = any(o.neg for o in self.ops) or any(n for _, n in self.goals)
        self.unit_cost = all(o.cost == 1 for o in self.ops)
        # Index each operator under its least frequent precondition fact: a state only looks at the
        # buckets of its true facts, so rare facts keep the buckets small.
        freq = [0] * len(self.atoms)
        for o in self.ops:
            for f in o.pre:
                freq[f] += 1
        self.by_fact = [[] for _ in self.atoms]
        self.always = []
        rarest = freq.__getitem__  # ties: the first in ``pre``, the lowest id (ids are ascending)
        for i, o in enumerate(self.ops):
            if o.pre:
                self.by_fact[min(o.pre, key=rarest)].append(i)
            else:
                self.always.append(i)
        # The facts that index some operator: a state's other true facts (visitall's visited
        # cells) are never looked at by ``applicable``.
        self.index_mask = mask(tuple(f for f, ops in enumerate(self.by_fact) if ops))

    def _build_axioms(self) -> None:
        """Evaluation tables of the axioms, stratum by stratum (see ``close``)."""
        self.derived_mask = mask(tuple({a for ax in self.axioms for a in ax.add}))
        self._layers = []
        if not self.axioms:
            return
        by_stratum: dict[int, list[GroundOp]] = {}
        for ax, k in zip(self.axioms, self.axiom_strata, strict=True):
            by_stratum.setdefault(k, []).append(ax)
        for k in sorted(by_stratum):
            group = by_stratum[k]
            heads = {a for ax in group for a in ax.add}
            rows: list[tuple[int, int, int, int, int]] = []
            waiting: dict[int, list[int]] = {}
            for j, ax in enumerate(group):
                same = [a for a in ax.pre if a in heads]
                other = mask(tuple(a for a in ax.pre if a not in heads))
                head = ax.add[0]
                rows.append((other, mask(ax.neg), 1 << head, head, len(same)))
                for a in same:
                    waiting.setdefault(a, []).append(j)
            self._layers.append((rows, waiting))
        self.init = self.close(self.init)

    def close(self, state: int) -> int:
        """``state`` with its derived atoms recomputed: the stratified least fixpoint of the axioms
        over its basic atoms (per stratum, FF-style precondition counters)."""
        state &= ~self.derived_mask
        for rows, waiting in self._layers:
            counts: dict[int, int] = {}
            queue: list[int] = []
            for j, (other, neg, bit, head, nsame) in enumerate(rows):
                if state & other == other and not state & neg:
                    if nsame:
                        counts[j] = nsame
                    elif not state & bit:
                        state |= bit
                        queue.append(head)
            while queue:
                for j in waiting.get(queue.pop(), ()):
                    c = counts.get(j)
                    if c is None:
                        continue
                    counts[j] = c = c - 1
                    if not c:
                        bit = rows[j][2]
                        if not state & bit:
                            state |= bit
                            queue.append(rows[j][3])
        return state

    def applicable(self, state: int) -> list[int]:
        """Ids of the operators applicable in ``state``, ascending."""
        pre_mask, neg_mask, by_fact = self.pre_mask, self.neg_mask, self.by_fact
        out = [i for i in self.always if not state & neg_mask[i]]
        s = state & self.index_mask
        while s:
            low = s & -s
            s ^= low
            for i in by_fact[low.bit_length() - 1]:
                if state & pre_mask[i] == pre_mask[i] and not state & neg_mask[i]:
                    out.append(i)
        out.sort()
        return out

    def apply(self, state: int, op: int) -> int:
        """The successor of ``state`` under operator ``op`` (conditional effects read the old state)."""
        add, dele = self.add_mask[op], self.del_mask[op]
        for cp, cn, ca, cd in self.cond_mask[op]:
            if state & cp == cp and not state & cn:
                add |= ca
                dele |= cd
        if self._layers:
            return self.close((state & ~dele) | add)
        return (state & ~dele) | add

    def is_goal(self, state: int) -> bool:
        """True when some goal disjunct holds in ``state``."""
        return any(state & p == p and not state & n for p, n in self.goal_masks)

    def to_plan(self, ops: list[int]) -> Plan:
        """The gsr.step.Plan for a sequence of operator ids."""
        return Plan(tuple(Step(self.ops[i].name, self.ops[i].args) for i in ops))

    def cost_of(self, ops: list[int]) -> float:
        """Total cost of an operator sequence."""
        return sum(self.ops[i].cost for i in ops)
