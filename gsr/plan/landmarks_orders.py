"""Orderings of a landmark graph beyond the greedy-necessary ones: natural and reasonable orders.

- *Natural* ``A -> B``: B cannot be reached in the delete relaxation without A (the landmark
  backchaining's "reachable without A" exploration, reused), so A is true before B in every plan.
- *Reasonable* ``A ->r B`` (Hoffmann, Porteous & Sebastia 2004, approximated as in LAMA and Fast
  Downward's ``lm_reasonable_orders_hps``): achieving A while B holds is impossible (B
  *interferes* with A), so a plan that reaches B first must destroy B and reach it again. B
  interferes with A when A and B are mutex, or every operator adding A also adds a fact E mutex
  with B (or deletes B). The pairs tried: for a goal landmark B, every other landmark A; for another
  landmark B with a greedy-necessary successor C, the other natural-or-stronger predecessors of C
  and their ancestors.
- *Obedient-reasonable*: the same test on the graph with the reasonable orders in it (the pairs
  reasonable assuming the reasonable orders are obeyed; Richter & Westphal's LAMA).

Only single-fact landmarks get reasonable orders, and only towards a landmark not true at the
start. The orders used for acceptance stay acyclic: a reasonable order closing a cycle is left out.
Mutexes come from ``gsr.plan.landmarks_mutex``; extended facts (a complement "not x") are mutex
with x only.
"""

from __future__ import annotations

from gsr.plan.landmarks_mutex import MutexGroups
from gsr.plan.task import Task, bits

MAX_NATURAL = 1500  # natural orders cost landmarks^2 mask tests: skipped above this many landmarks


class Orders:
    """Natural, reasonable and obedient-reasonable orders of a landmark graph.

    Inputs: the task, the landmark facts over extended fact ids (``n`` atoms, then the complements
    of ``negated``), the greedy-necessary parents (bitmasks), the goal landmarks, the initially true
    extended facts and, per landmark, the extended facts reachable without it (``reach``).
    Outputs: ``natural``, ``reasonable`` and ``obedient`` as lists of (before, after) pairs, and
    ``accept_parents``: per landmark the bitmask of landmarks that must be accepted first
    (greedy-necessary, reasonable and obedient-reasonable orders).
    """

    def __init__(
        self,
        task: Task,
        facts: list[tuple[int, ...]],
        negated: list[int],
        gn_parents: list[int],
        goal_mask: int,
        init_ext: int,
        reach: dict[int, int],
        mutexes: MutexGroups,
        obedient: bool = False,
    ) -> None:
        self.task = task
        self.facts = facts
        self.n = len(task.atoms)
        self.negated = negated
        self.mutexes = mutexes
        m = len(facts)
        self.init_true = [any(init_ext >> f & 1 for f in fs) for fs in facts]
        self.simple = [len(fs) == 1 for fs in facts]
        self._shared: dict[int, frozenset[int]] = {}
        self._achievers = self._index_achievers()
        # Natural orders from the "reachable without" explorations.
        natural_par = [0] * m
        self.natural: list[tuple[int, int]] = []
        if m <= MAX_NATURAL:
            fact_mask = [sum(1 << f for f in fs) for fs in facts]
            for k, reached in reach.items():
                if reached == -1:
                    continue
                for j in range(m):
                    if j != k and not self.init_true[j] and not fact_mask[j] & reached:
                        natural_par[j] |= 1 << k
                        if not gn_parents[j] >> k & 1:
                            self.natural.append((k, j))
        strong_par = [g | nat for g, nat in zip(gn_parents, natural_par, strict=True)]
        gn_children: list[list[int]] = [[] for _ in range(m)]
        for j, par in enumerate(gn_parents):
            for p in bits(par):
                gn_children[p].append(j)
        self.accept_parents = list(gn_parents)
        self._children: list[set[int]] = [set() for _ in range(m)]
        for j, par in enumerate(gn_parents):
            for p in bits(par):
                self._children[p].add(j)
        self.reasonable = self._approximate(strong_par, gn_children, goal_mask, None)
        self.obedient: list[tuple[int, int]] = []
        if obedient:
            r_children: list[list[int]] = [[] for _ in range(m)]
            r_par = [0] * m
            for a, b in self.reasonable:
                r_children[a].append(b)
                r_par[b] |= 1 << a
            done = set(self.reasonable)
            self.obedient = [
                pair
                for pair in self._approximate(
                    [s | r for s, r in zip(strong_par, r_par, strict=True)], r_children, 0, done
                )
                if pair not in done
            ]

    # -- interference ---------------------------------------------------------------------------

    def _index_achievers(self) -> dict[int, list[int]]:
        """Extended fact -> operators adding it unconditionally (a complement: deleting its atom)."""
        comp = {a: self.n + j for j, a in enumerate(self.negated)}
        out: dict[int, list[int]] = {}
        for i, o in enumerate(self.task.ops):
            for a in o.add:
                out.setdefault(a, []).append(i)
            for d in o.delete:
                c = comp.get(d)
                if c is not None:
                    out.setdefault(c, []).append(i)
        return out

    def _shared_effects(self, a: int) -> frozenset[int]:
        """Effects every unconditional achiever of extended fact ``a`` has: added atoms as their
        ids, deleted atoms ``d`` as ``-d - 1``."""
        found = self._shared.get(a)
        if found is None:
            shared: set[int] | None = None
            ops = self.task.ops
            for i in self._achievers.get(a, ()):
                o = ops[i]
                eff = {*o.add, *(-d - 1 for d in o.delete)}
                shared = eff if shared is None else shared & eff
                if not shared:
                    break
            found = self._shared[a] = frozenset(shared or ())
        return found

    def _mutex(self, x: int, y: int) -> bool:
        """Extended facts ``x`` and ``y`` never hold together."""
        n = self.n
        if x >= n and y >= n:
            return False
        if x >= n:
            return self.negated[x - n] == y
        if y >= n:
            return self.negated[y - n] == x
        return self.mutexes.mutex(x, y)

    def interferes(self, a: int, b: int) -> bool:
        """Fact ``b`` interferes with achieving fact ``a``: a plan reaching ``b`` first loses it."""
        if a == b:
            return False
        if self._mutex(a, b):
            return True
        for e in self._shared_effects(a):
            if e < 0:
                if b == -e - 1:  # every achiever of a deletes b
                    return True
            elif e != a and self._mutex(e, b):  # (a complement b: every achiever adds its atom)
                return True
        return False

    # -- orders -----------------------------------------------------------------------------------

    def _reaches(self, start: int, target: int) -> bool:
        """``target`` follows ``start`` in the acceptance orders."""
        stack, seen = [start], {start}
        children = self._children
        while stack:
            k = stack.pop()
            for c in children[k]:
                if c == target:
                    return True
                if c not in seen:
                    seen.add(c)
                    stack.append(c)
        return False

    def _approximate(
        self,
        strong_par: list[int],
        children: list[list[int]],
        goal_mask: int,
        known: set[tuple[int, int]] | None,
    ) -> list[tuple[int, int]]:
        """One pass of HPS's approximation (``goal_mask`` 0 and ``known`` set: the obedient pass)."""
        m = len(self.facts)
        facts, simple, init_true = self.facts, self.simple, self.init_true
        ancestors: dict[int, int] = {}

        def ancestors_of(k: int) -> int:
            found = ancestors.get(k)
            if found is None:
                found = 0
                stack = list(bits(strong_par[k]))
                while stack:
                    p = stack.pop()
                    if not found >> p & 1:
                        found |= 1 << p
                        stack.extend(bits(strong_par[p]))
                ancestors[k] = found
            return found

        out: list[tuple[int, int]] = []
        for b in range(m):
            if not simple[b] or init_true[b]:
                continue
            if goal_mask >> b & 1:
                candidates = [a for a in range(m) if a != b and simple[a]]
            else:
                cand = 0
                for c in children[b]:
                    for p in bits(strong_par[c]):
                        if p != b and simple[p]:
                            cand |= 1 << p | ancestors_of(p)
                candidates = [a for a in bits(cand) if a != b and simple[a]]
            fb = facts[b][0]
            for a in candidates:
                if known is not None and (a, b) in known:
                    continue
                if strong_par[a] >> b & 1 or self.accept_parents[b] >> a & 1:
                    continue
                if not self.interferes(facts[a][0], fb):
                    continue
                if self._reaches(b, a):
                    continue  # would close a cycle of acceptance orders
                out.append((a, b))
                self.accept_parents[b] |= 1 << a
                self._children[a].add(b)
        return out
