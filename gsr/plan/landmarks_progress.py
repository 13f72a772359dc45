"""Landmark progression with past and future landmarks (Büchner, Keller, Eriksson & Helmert 2023).

The landmark status of a state is a pair of bitsets over the landmarks of a ``Landmarks`` graph:

- *past*: landmarks that held in some state of the path (the initial state included), whatever
  their predecessors;
- *future*: landmarks that still have to be reached: not past, or past but false now and needed
  again. Going from a parent's status to a successor state ``s``:

  1. a future landmark stays future unless it holds in ``s``; past gains what holds in ``s``;
  2. a goal landmark false in ``s`` is future;
  3. a greedy-necessary order ``A -> B`` with B not past makes A future when A is false in ``s``
     (A must hold again right before B is first reached);
  4. a reasonable order ``A ->r B`` with A not past makes B future (B reached too early must be
     reached again after A).

The landmark-sum heuristic with unit costs counts the future landmarks, infinite when one of them
has no achiever. This is Fast Downward's ``landmark_status_manager`` and ``landmark_sum`` as used by
``lama-first`` (its lazy search keeps the status of the path that first reached a state, the same
here). It differs from ``Landmarks.accept``/``Landmarks.value``, which accept a landmark only after
its greedy-necessary and reasonable predecessors and count unaccepted ones.
"""

from __future__ import annotations

from gsr.plan.heuristics import INF
from gsr.plan.landmarks import Landmarks
from gsr.plan.task import bits


class Progression:
    """Past/future landmark status of states and the unit-cost landmark-sum heuristic."""

    def __init__(self, lm: Landmarks) -> None:
        self.lm = lm
        m = self.m = len(lm.lm_facts)
        self.pos_lms = {a: sum(1 << k for k in ks) for a, ks in lm.by_pos.items()}
        self.neg_lms = {a: sum(1 << k for k in ks) for a, ks in lm.by_neg.items()}
        self.pos_union, self.neg_union = lm.pos_union, lm.neg_union
        self.goal_mask = lm.goal_mask
        self.gn_parents = lm.gn_parents
        reasonable = lm.orders.reasonable if lm.orders is not None else []
        heads: dict[int, int] = {}
        for tail, head in reasonable:
            heads[tail] = heads.get(tail, 0) | 1 << head
        self.r_heads = list(heads.items())  # reasonable tail -> bitmask of its heads
        achievable = 0  # landmarks some operator adds (one that none adds is lost once false)
        for mask in lm.lm_add_mask.values():
            achievable |= mask
        self.unachievable = ((1 << m) - 1) & ~achievable
        self._again: dict[int, int] = {}  # past -> landmarks greedy-necessarily before a non-past one
        self._early: dict[int, int] = {}  # past -> heads of reasonable orders whose tail is not past

    def holding(self, state: int) -> int:
        """The landmarks that hold in ``state``, as a bitmask."""
        out = 0
        if self.m:
            pos_lms, neg_lms = self.pos_lms, self.neg_lms
            for a in bits(state & self.pos_union):
                out |= pos_lms[a]
            for a in bits(self.neg_union & ~state):
                out |= neg_lms[a]
        return out

    def initial(self, state: int) -> tuple[int, int]:
        """The status of the initial state: past what holds, future the rest and any landmark
        holding initially that has a predecessor."""
        true = self.holding(state)
        fut = ((1 << self.m) - 1) & ~true
        for k in bits(true):
            if self.gn_parents[k]:
                fut |= 1 << k
        for _tail, heads in self.r_heads:
            fut |= heads & true
        return self._orders(true, fut, true)

    def progress(self, status: tuple[int, int], state: int) -> tuple[int, int]:
        """The status of ``state`` reached from a state with ``status``."""
        past, fut = status
        true = self.holding(state)
        return self._orders(past | true, (fut & ~true) | (self.goal_mask & ~true), true)

    def _orders(self, past: int, fut: int, true: int) -> tuple[int, int]:
        again = self._again.get(past)
        if again is None:
            again = 0
            gn = self.gn_parents
            for k in bits(((1 << self.m) - 1) & ~past):
                again |= gn[k]
            self._again[past] = again
        early = self._early.get(past)
        if early is None:
            early = 0
            for tail, heads in self.r_heads:
                if not past >> tail & 1:
                    early |= heads
            self._early[past] = early
        return past, fut | (again & ~true) | early

    def value(self, status: tuple[int, int]) -> float:
        """Unit-cost landmark sum: the number of future landmarks (INF when one cannot be added)."""
        fut = status[1]
        if fut & self.unachievable:
            return INF
        return fut.bit_count()

    def preferred(
        self, status: tuple[int, int], applicable: list[int], adds: dict[int, int] | None = None
    ) -> list[int]:
        """Applicable operators adding a future landmark (Fast Downward's ``pref=true``); ``adds``
        as in ``Landmarks.value``."""
        fut = status[1]
        if adds is None:
            adds = self.lm.lm_add_mask
        return [i for i in applicable if adds.get(i, 0) & fut]
