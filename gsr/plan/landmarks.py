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

from time import perf_counter

from gsr.plan import relax_jit
from gsr.plan.task import Task, bits


class Landmarks:
    """The landmark graph of a task (facts are atom ids) and the landmark-count heuristic."""

    def __init__(self, task: Task, limit: int = 2000) -> None:
        self.task = task
        self.facts: list[int] = []  # landmark index -> atom id
        self.parents: list[int] = []  # landmark index -> bitmask of landmarks ordered before it
        self.goal_mask = 0  # landmark indices that are goals
        self._py_time = 0.0  # seconds of Python exploration (then the compiled one takes over)
        self._compiled = None  # relax_c.CReach or relax_jit.CompiledReach once compiled
        self._compile_after = relax_jit.C_AFTER  # seconds of Python exploration before compiling
        self._unary: tuple[dict[int, list[int]], list[tuple[int, ...]], list[int], list[int]] | None = None
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
        self.union = sum(self.fact_mask)  # the atoms that are landmarks
        self.goal_lms = [(k, self.fact_mask[k]) for k in bits(self.goal_mask)]
        self.lm_adds: dict[int, list[int]] = {}  # operator -> the landmarks it adds
        self.lm_add_mask: dict[int, int] = {}  # operator -> bitmask of the landmarks it adds
        # Per accepted set (a path-dependent value shared by many states): the atoms of its
        # landmarks, and the landmarks ready next (not accepted, every predecessor accepted).
        self._accepted_atoms: dict[int, int] = {}
        self._ready: dict[int, int] = {}
        for k, ops in enumerate(self.achievers):
            for i in ops:
                self.lm_adds.setdefault(i, []).append(k)
                self.lm_add_mask[i] = self.lm_add_mask.get(i, 0) | 1 << k

    def _reachable_without(self, fact: int):
        """Which operators are applicable in the delete relaxation when ``fact`` is never added
        (conditional effects and negative preconditions ignored: an over-approximation)."""
        task = self.task
        pre_mask = task.pre_mask
        if task.axioms:
            return lambda i: True  # derived preconditions: do not prune achievers through them
        if self._unary is None:
            self._build_unary()
        pre_of, adds, npre, no_pre = self._unary
        if self._compiled is not None:
            reached = self._compiled.reached(fact)
            return lambda i: reached & pre_mask[i] == pre_mask[i]
        start = perf_counter()
        # Counter-based exploration (each precondition edge visited once, as in FF's h_add).
        unsat = npre[:]
        seen = bytearray(len(task.atoms))
        queue = bits(task.init & ~(1 << fact))
        for f in queue:
            seen[f] = 1
        seen[fact] = 1  # never added
        for u in no_pre:
            for g in adds[u]:
                if not seen[g]:
                    seen[g] = 1
                    queue.append(g)
        for f in queue:  # the queue grows while it is read
            for u in pre_of.get(f, ()):
                unsat[u] -= 1
                if not unsat[u]:
                    for g in adds[u]:
                        if not seen[g]:
                            seen[g] = 1
                            queue.append(g)
        reached = 0
        for f in queue:
            reached |= 1 << f
        self._py_time += perf_counter() - start
        check = self._compile_after
        if self._py_time > check and relax_jit.allowed():
            # Many landmarks on a large task (visitall: one per cell): the rest run compiled (the C
            # kernels after C_AFTER seconds, numba only after JIT_AFTER).
            init = bits(task.init)
            numba = check >= relax_jit.JIT_AFTER
            self._compiled = relax_jit.compiled_reach(
                len(task.atoms), init, pre_of, adds, npre, no_pre, numba
            )
            if self._compiled is None:
                self._compile_after = relax_jit.JIT_AFTER if not numba else float("inf")
        return lambda i: reached & pre_mask[i] == pre_mask[i]

    def _build_unary(self) -> None:
        """One relaxed operator per operator (its precondition atoms, its adds) and one per
        conditional effect (precondition plus effect condition atoms, the effect's adds)."""
        pre_of: dict[int, list[int]] = {}
        adds: list[tuple[int, ...]] = []
        npre: list[int] = []
        for o in self.task.ops:
            for pre, add in ((o.pre, o.add), *(((*o.pre, *cp), ca) for cp, _cn, ca, _cd in o.cond)):
                if not add:
                    continue
                u = len(adds)
                pres = set(pre)
                for p in pres:
                    pre_of.setdefault(p, []).append(u)
                adds.append(tuple(add))
                npre.append(len(pres))
        self._unary = (pre_of, adds, npre, [u for u, k in enumerate(npre) if not k])

    def accept(self, accepted: int, state: int) -> int:
        """The accepted landmarks after reaching ``state`` (``accepted``: those of its parent)."""
        if not self.facts:
            return 0
        # Candidates: landmarks true in the state and not accepted yet (usually none or a handful),
        # found on the atoms: the accepted landmarks' atoms are masked out first.
        done = self._accepted_atoms.get(accepted)
        if done is None:
            done = 0
            for k in bits(accepted):
                done |= self.fact_mask[k]
            self._accepted_atoms[accepted] = done
        fresh = state & self.union & ~done
        if not fresh:
            return accepted
        by_fact, parents = self.by_fact, self.parents
        todo = [by_fact[f] for f in bits(fresh)]
        changed = True
        while changed and todo:
            changed = False
            rest = []
            for k in todo:
                if accepted & parents[k] == parents[k]:
                    accepted |= 1 << k
                    changed = True
                else:
                    rest.append(k)
            todo = rest
        return accepted

    def value(self, accepted: int, state: int, applicable: list[int] | None = None) -> tuple[int, list[int]]:
        """Landmark count of a state with its accepted landmarks, and the preferred operators
        (``applicable``: the state's applicable operators, when the caller has them)."""
        if not self.facts:
            return 0, []
        missing = self.all_mask & ~accepted
        h = missing.bit_count()
        for k, mask in self.goal_lms:
            if accepted >> k & 1 and not state & mask:
                h += 1
        # Preferred: applicable operators adding a landmark not accepted whose predecessors are.
        task = self.task
        if applicable is None:
            applicable = task.applicable(state)
        ready = self._ready.get(accepted)
        if ready is None:
            parents = self.parents
            ready = 0
            for k in bits(missing):
                if accepted & parents[k] == parents[k]:
                    ready |= 1 << k
            self._ready[accepted] = ready
        if not ready:
            return h, []
        adds = self.lm_add_mask
        return h, [i for i in applicable if adds.get(i, 0) & ready]
