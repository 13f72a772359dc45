"""Fact landmarks by backchaining and the landmark-count heuristic (as in LAMA, simplified).

Landmarks are facts every plan makes true at some point. The goal facts are landmarks; going
backwards, the preconditions shared by every *first achiever* of a landmark (an operator adding it
that is applicable in the delete relaxation before the landmark itself is reached) are landmarks
too, ordered before it (greedy-necessary orderings; Zhu & Givan 2003, Richter, Helmert & Westphal
2008 without disjunctive landmarks and without the domain transition graph step).

The landmark-count heuristic is path-dependent: a landmark is *accepted* when it is true in a
state reached on the path and all landmarks ordered before it were accepted earlier; h counts the
landmarks not accepted, plus the accepted goal landmarks that are false again. Its preferred
operators are the applicable operators that add a landmark ready to be accepted (LAMA's
"simple" preferred operators).
"""

from __future__ import annotations

from gsr.plan.task import Task, bits


class Landmarks:
    """The landmark graph of a task (facts are atom ids) and the landmark-count heuristic."""

    def __init__(self, task: Task, limit: int = 2000) -> None:
        self.task = task
        self.facts: list[int] = []  # landmark index -> atom id
        self.parents: list[int] = []  # landmark index -> bitmask of landmarks ordered before it
        self.goal_mask = 0  # landmark indices that are goals
        if len(task.goals) != 1:  # a disjunctive goal: no fact is a landmark for sure
            return
        derived = task.derived_mask
        index: dict[int, int] = {}
        order: dict[int, set[int]] = {}  # fact -> facts ordered before it
        todo: list[int] = []
        for g in task.goals[0][0]:
            if not derived >> g & 1:
                index[g] = len(index)
                todo.append(g)
                self.goal_mask |= 1 << index[g]
        adders: dict[int, list[int]] = {}
        for i, o in enumerate(task.ops):
            for a in o.add:
                adders.setdefault(a, []).append(i)
        while todo and len(index) < limit:
            fact = todo.pop()
            if task.init >> fact & 1:
                continue  # true at the start: nothing needs to precede it
            reachable = self._reachable_without(fact)
            first = [i for i in adders.get(fact, ()) if reachable(i)]
            if not first:
                continue
            shared = set(task.ops[first[0]].pre)
            for i in first[1:]:
                shared &= set(task.ops[i].pre)
                if not shared:
                    break
            for p in shared:
                if derived >> p & 1:
                    continue
                order.setdefault(fact, set()).add(p)
                if p not in index:
                    index[p] = len(index)
                    todo.append(p)
        self.facts = [0] * len(index)
        for fact, k in index.items():
            self.facts[k] = fact
        self.parents = [0] * len(index)
        for fact, before in order.items():
            for p in before:
                self.parents[index[fact]] |= 1 << index[p]
        self.fact_mask = [1 << f for f in self.facts]
        self.all_mask = (1 << len(self.facts)) - 1
        self.by_fact = index
        # Operators that add each landmark (preferred operators).
        self.achievers = [adders.get(f, []) for f in self.facts]

    def _reachable_without(self, fact: int):
        """Which operators are applicable in the delete relaxation when ``fact`` is never added
        (conditional effects and negative preconditions ignored: an over-approximation)."""
        task = self.task
        reached = task.init & ~(1 << fact)
        ops = task.ops
        pre_mask, add_mask = task.pre_mask, task.add_mask
        no_fact = ~(1 << fact)
        live = list(range(len(ops)))
        changed = True
        while changed:
            changed = False
            rest = []
            for i in live:
                if reached & pre_mask[i] == pre_mask[i]:
                    new = reached | (add_mask[i] & no_fact)
                    for cp, _cn, ca, _cd in task.cond_mask[i]:
                        if reached & cp == cp:
                            new |= ca & no_fact
                    if new != reached:
                        reached = new
                        changed = True
                else:
                    rest.append(i)
            live = rest
        if task.axioms:
            reached = ~0  # derived preconditions: do not prune achievers through them
        return lambda i: reached & pre_mask[i] == pre_mask[i]

    def accept(self, accepted: int, state: int) -> int:
        """The accepted landmarks after reaching ``state`` (``accepted``: those of its parent)."""
        if not self.facts:
            return 0
        parents, fact_mask = self.parents, self.fact_mask
        changed = True
        while changed:
            changed = False
            for k in range(len(fact_mask)):
                bit = 1 << k
                if not accepted & bit and state & fact_mask[k] and accepted & parents[k] == parents[k]:
                    accepted |= bit
                    changed = True
        return accepted

    def value(self, accepted: int, state: int) -> tuple[int, list[int]]:
        """Landmark count of a state with its accepted landmarks, and the preferred operators."""
        if not self.facts:
            return 0, []
        missing = self.all_mask & ~accepted
        h = missing.bit_count()
        regained = accepted & self.goal_mask
        for k in bits(regained):
            if not state & self.fact_mask[k]:
                h += 1
        preferred = []
        task = self.task
        pre_mask, neg_mask = task.pre_mask, task.neg_mask
        for k in bits(missing):
            if accepted & self.parents[k] == self.parents[k]:
                for i in self.achievers[k]:
                    if state & pre_mask[i] == pre_mask[i] and not state & neg_mask[i]:
                        preferred.append(i)
        return h, preferred
