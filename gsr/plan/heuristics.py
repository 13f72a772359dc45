"""Delete-relaxation heuristics over integer-indexed unary operators: h_add/FF, h_max and LM-cut.

Every ground operator becomes one unary operator per effect group (its unconditional adds, and
one per conditional effect with the condition added to the precondition); a goal disjunct is a
zero-cost unary operator reaching the auxiliary fact ``G``; an always-true fact ``T`` is the
precondition of operators without one, so that the counter-based Dijkstra (as in FF / Fast
Downward's relaxation heuristics) needs no special cases. Negative preconditions and goals are
compiled into complement facts (see Relaxation), which keeps h_max and LM-cut admissible.
"""

from __future__ import annotations

from heapq import heappop, heappush
from time import perf_counter, process_time

from gsr.plan import relax_jit
from gsr.plan.task import Task

INF = float("inf")


def _drain(bucket: list[int]):
    """The bucket's entries last in first out, including those pushed while it is drained."""
    while bucket:
        yield bucket.pop()


class Relaxation:
    """The unary-operator relaxation of a Task, shared by all heuristics."""

    # h_add starts from the reference state's level 0 unless more than 1/far of the facts differ
    # (then counting the state's facts from scratch is cheaper; measured on blocks and tabletop).
    far = 8

    def __init__(self, task: Task, unit: bool = False) -> None:
        """``unit``: every operator costs 1 in the relaxation (Fast Downward's cost type "one", as
        lama-first's heuristics use): on tasks with action costs the greedy searches then look for
        short plans first instead of crawling through cheap steps; h_max and LM-cut need the real
        costs (unit=False) to stay admissible."""
        n = len(task.atoms)
        self.task = task
        self.unit = unit
        self._lifo = False  # see the ``lifo`` property
        self.goal_fact = n
        self.true_fact = n + 1
        # Negative preconditions, effect conditions and goals become complement facts "not a" (true
        # in a state without a, achieved by deleting a), so that the relaxation sees that a drawer
        # must be closed or a blocker moved; the compiled task is equivalent, so h_max and LM-cut
        # stay admissible.
        # Derived atoms get no complement: nothing deletes them, so a negated derived atom is
        # simply assumed true in the relaxation (dropping a condition: h_max and LM-cut stay
        # admissible). Axioms are zero-cost unary operators (their body, their head).
        conds = {id(o.cond): o.cond for o in task.ops}.values()  # grounding shares cond tuples
        derived = {a for ax in task.axioms for a in ax.add}
        negated = sorted(
            (
                {a for o in (*task.ops, *task.axioms) for a in o.neg}
                | {a for cond in conds for _cp, cn, _ca, _cd in cond for a in cn}
                | {a for _p, ng in task.goals for a in ng}
            )
            - derived
        )
        self.comp = {a: n + 2 + k for k, a in enumerate(negated)}
        self.comp_pairs = [(1 << a, c) for a, c in self.comp.items()]
        comp = self.comp
        n_facts = n + 2 + len(negated)
        pre: list[tuple[int, ...]] = []
        add: list[tuple[int, ...]] = []
        cost: list[float] = []
        owner: list[int] = []
        # Conditional effects hang off an auxiliary fact instead of repeating the operator's whole
        # precondition in every effect group; effect groups (condition, adds) shared by several
        # operators hang off one fact "one of these operators fired". The cube-counting effects of
        # the tabletop domain (one group per count, for every pick and place of a cube) were ~80%
        # of the unary operators. h_add and h_FF are unchanged (h(aux) = min over the operators,
        # and the sum distributes over the min); h_max can only get lower (max(c + h(pre),
        # h(cond)) <= c + max(h(pre), h(cond))), so it stays admissible.
        users: dict[tuple[tuple[int, ...], tuple[int, ...]], list[int]] = {}
        keys: dict[tuple, tuple[tuple[int, ...], tuple[int, ...]] | None] = {}  # per distinct effect
        # Grounding shares cond tuples between operators: the operators of each distinct tuple (in
        # order of first use), so that each effect's users are extended once per tuple.
        sharing: dict[int, tuple[tuple, list[int]]] = {}
        for i, o in enumerate(task.ops):
            if o.cond:
                found = sharing.get(id(o.cond))
                if found is None:
                    sharing[id(o.cond)] = (o.cond, [i])
                else:
                    found[1].append(i)
        merged: dict[int, list[int]] = {}  # users lists extended more than once (to sort, dedupe)
        for cond, ops_of_cond in sharing.values():
            for ce in cond:
                if ce in keys:
                    ukey = keys[ce]
                else:
                    cp, cn, ca, cd = ce
                    ga = (*ca, *[comp[d] for d in cd if d in comp])
                    ukey = keys[ce] = ((*cp, *[comp[a] for a in cn if a in comp]), ga) if ga else None
                if ukey is not None:
                    ops_of = users.setdefault(ukey, [])
                    if ops_of:
                        merged[id(ops_of)] = ops_of
                    ops_of += ops_of_cond
        for ops_of in merged.values():  # ascending, each operator once (as one pass over the ops gives)
            ops_of[:] = sorted(set(ops_of))
        aux_of: dict[tuple[int, ...], int] = {}  # operator set -> its "one of them fired" fact
        aux_adds: dict[int, list[int]] = {}
        for (gp, ga), ops_of in users.items():
            key = tuple(ops_of)
            aux = aux_of.get(key)
            if aux is None:
                aux = aux_of[key] = n_facts
                n_facts += 1
                for i in ops_of:
                    aux_adds.setdefault(i, []).append(aux)
            pre.append((aux, *gp))
            add.append(ga)
            cost.append(0)
            owner.append(-1)  # the relaxed plan reaches the operator through the aux fact's supporter
        true_pre = (self.true_fact,)
        for i, o in enumerate(task.ops):
            # (Tuples from lists: a generator per operator cost more than the lists.)
            if o.neg:
                base_pre = (*o.pre, *[comp[a] for a in o.neg if a in comp]) or true_pre
            else:
                base_pre = o.pre or true_pre
            base_add = (*o.add, *[comp[d] for d in o.delete if d in comp], *aux_adds.get(i, ()))
            if base_add:
                pre.append(base_pre)
                add.append(base_add)
                cost.append(1 if unit else o.cost)
                owner.append(i)
        for ax in task.axioms:
            pre.append((*ax.pre, *(comp[a] for a in ax.neg if a in comp)) or (self.true_fact,))
            add.append(ax.add)
            cost.append(0)
            owner.append(-1)  # the relaxed plan goes on through the axiom's body
        self.n_facts = n_facts
        for p, ng in task.goals:
            gp = (*p, *(comp[a] for a in ng if a in comp))
            pre.append(gp or (self.true_fact,))
            add.append((self.goal_fact,))
            cost.append(0)
            owner.append(-1)
        self.pre, self.add, self.cost, self.owner = pre, add, cost, owner
        # With one goal disjunct, G has one achiever: its cost and supporter are final as soon as
        # that operator fires (all goal atoms settled), so h_add stops there instead of settling
        # every fact cheaper than the sum of the goal atoms' costs. h_add(G), h_FF and the relaxed
        # plan are unchanged: they only read settled facts, whose costs and supporters are final.
        self.goal_stop = self.goal_fact if len(task.goals) == 1 else -1
        self.npre = [len(p) for p in pre]
        self.pre_of: list[list[int]] = [[] for _ in range(self.n_facts)]
        pre_of = self.pre_of
        for u, p in enumerate(pre):
            for f in p:
                pre_of[f].append(u)
        self._achievers: list[list[int]] | None = None  # LM-cut only: built on first use
        self._inf = [INF] * self.n_facts
        self._none = [-1] * self.n_facts
        # Integer costs allow a bucket queue instead of a binary heap (measured ~20% faster h_add).
        self.integral = all(float(c).is_integer() and c >= 0 for c in set(cost))
        if self.integral:
            self.cost = [int(c) for c in cost]
        # Level 0 of h_add relative to a reference state (the initial state): the precondition
        # counters after counting the state's facts, and the operators they enable. A state is
        # evaluated from it by adjusting only the facts that differ (a few atoms and their
        # complements) instead of counting down every true fact (~200 of them on tabletop tasks).
        self.comp_of = [-1] * n
        for a, c in self.comp.items():
            self.comp_of[a] = c
        self.ref = task.init
        self._ref_built = False  # the reference level is built on the first Python h_add
        # The last h_add result: plan()'s reachability check and the search's first evaluation are
        # both of the initial state. Callers only read the returned lists.
        self._last: tuple[int, tuple[list[float], list[int]]] | None = None
        # Large tasks: the same h_add and relaxed plans compiled by numba when it is installed, from
        # the start on large relaxations, or once Python h_FF has taken JIT_AFTER seconds of wall
        # time and the search as much CPU time (small searches, the tabletop ones among them, never
        # pay numba's import).
        self._jit = None
        self._jit_ff = None
        # The search's successor generator: Task.applicable, or its C twin once the C kernels are
        # loaded for the relaxation (same ids, same order).
        self.applicable = task.applicable
        self._py_time = 0.0  # wall seconds spent in Python h_FF
        # ... at which the CPU time is looked at next: the C kernels are tried first (cheap to load),
        # numba from JIT_AFTER on.
        self._jit_check = relax_jit.C_AFTER
        self._jit_stage = relax_jit.C_AFTER  # CPU seconds since construction before compiling
        self._cpu0 = process_time()
        self._jit_open = self.integral and relax_jit.allowed()
        if self._jit_open and relax_jit.wanted(sum(self.npre)):
            self._use_jit()

    @property
    def compiled(self):
        """The compiled h_add / h_FF in use (``relax_c.CRelaxation`` or numba's), or None."""
        return self._jit

    @property
    def lifo(self) -> bool:
        """Experimental (issue 18, fifth pass): h_add pops its cost buckets above 0 last in first
        out, as Fast Downward's bucket queue does, instead of first in first out. The costs are the
        same; the best supporters among equally cheap ones, so h_FF's relaxed plan and preferred
        operators, differ. Python path and C kernels (not numba); off by default."""
        return self._lifo

    @lifo.setter
    def lifo(self, value: bool) -> None:
        if value and self._jit is not None and not hasattr(self._jit, "set_lifo"):
            raise ValueError("last-in-first-out h_add buckets need the C kernels or the Python path")
        self._lifo = bool(value)
        self._last = None  # a cached h_add of the other order
        if self._jit is not None and hasattr(self._jit, "set_lifo"):
            self._jit.set_lifo(self._lifo)

    def _facts(self, state: int) -> list[int]:
        """The facts true in ``state``: its atoms, the always-true fact and the true complements."""
        out = []
        s = state
        while s:
            low = s & -s
            s ^= low
            out.append(low.bit_length() - 1)
        out.append(self.true_fact)
        out += [c for bit, c in self.comp_pairs if not state & bit]
        return out

    def _start(self, state: int) -> list[tuple[float, int]]:
        heap = []
        s = state
        while s:
            low = s & -s
            s ^= low
            heap.append((0, low.bit_length() - 1))
        heap.append((0, self.true_fact))
        heap += [(0, c) for bit, c in self.comp_pairs if not state & bit]
        return heap

    def _use_jit(self, numba: bool = True) -> None:
        """Switch to the compiled relaxation (the C kernels, or numba when ``numba``); the Python
        path stays when neither is available."""
        self._jit = relax_jit.compiled(self, numba=numba)
        self._jit_ff = getattr(self._jit, "ff", None)
        if self._jit is not None or numba:
            self._jit_open = False
        if self._jit is not None and relax_jit.c_library() is not None:
            from gsr.plan.relax_c import CRelaxation, CSuccessors

            shared = self._jit if isinstance(self._jit, CRelaxation) else None
            self.applicable = CSuccessors(self.task, relax_jit.c_library(), shared).applicable

    def hadd(self, state: int) -> tuple[list[float], list[int]]:
        """h_add costs of all facts (stopping once G is settled) and each fact's best supporter."""
        last = self._last
        if last is not None and last[0] == state:
            return last[1]
        if self._jit is not None:
            jit = self._jit
            jit.hadd(state)
            found = (
                [INF if c >= relax_jit.UNREACHED else c for c in jit.cost.tolist()],
                jit.sup.tolist(),
            )
            self._last = (state, found)
            return found
        found = self._hadd_buckets(state) if self.integral else self._hadd_heap(state)
        self._last = (state, found)
        return found

    def _hadd_heap(self, state: int) -> tuple[list[float], list[int]]:
        """h_add with a binary heap (non-integer operator costs)."""
        cost = self._inf[:]
        sup = self._none[:]
        unsat = self.npre[:]
        acc = self.cost[:]
        pre_of, add, goal = self.pre_of, self.add, self.goal_fact
        heap = self._start(state)
        for _, f in heap:
            cost[f] = 0
        while heap:
            c, f = heappop(heap)
            if c > cost[f]:
                continue
            if f == goal:
                break
            for u in pre_of[f]:
                acc[u] += c
                unsat[u] -= 1
                if not unsat[u]:
                    v = acc[u]
                    for g in add[u]:
                        if v < cost[g]:
                            cost[g] = v
                            sup[g] = u
                            heappush(heap, (v, g))
        return cost, sup

    def _build_reference(self) -> None:
        """The Python h_add's level 0 at the reference state and its packed counters (built on
        first use: a relaxation that runs compiled from the start never needs them)."""
        task, pre = self.task, self.pre
        ref_facts = [f for _, f in self._start(task.init)]
        self._ref_unsat = self.npre[:]
        self._ref_cost = self._inf[:]
        for f in ref_facts:
            self._ref_cost[f] = 0
            for u in self.pre_of[f]:
                self._ref_unsat[u] -= 1
        # Enabled operators fire in the order a fact-by-fact count would fire them (by their highest
        # precondition id, then id), so supporters and h_FF's relaxed plans do not change.
        order = sorted(range(len(pre)), key=[max(p) for p in pre].__getitem__)  # stable: ties by id
        self._rank = [0] * len(pre)
        for r, u in enumerate(order):
            self._rank[u] = r
        self._ref_zero = sorted(
            (u for u, k in enumerate(self._ref_unsat) if not k), key=self._rank.__getitem__
        )
        # Packed counters of the bucket h_add (see _hadd_buckets): x = K * cost - unsettled.
        self._shift = max(self.npre, default=0).bit_length()
        self._low_bits = (1 << self._shift) - 1
        if self.integral:
            self._x0 = [(int(c) << self._shift) - k for c, k in zip(self.cost, self.npre, strict=True)]
            self._ref_x = [
                (int(c) << self._shift) - k for c, k in zip(self.cost, self._ref_unsat, strict=True)
            ]
        self._ref_built = True

    def _hadd_buckets(self, state: int) -> tuple[list[float], list[int]]:
        """h_add with a bucket queue indexed by (integer) cost; same costs as the heap version.

        Each unary operator's counter packs its accumulated cost and its number of unsettled
        preconditions into one int, ``x = K * acc - unsat`` (K a power of two above every
        precondition count): settling a precondition at cost c is ``x += K * c + 1``, the operator
        fires when ``x & (K - 1)`` is 0 and its cost is then ``x >> shift``. One list read and write
        per edge instead of two (the inner loop is most of the search time).
        """
        if not self._ref_built:
            self._build_reference()
        sup = self._none[:]
        pre_of, add, goal = self.pre_of, self.add, self.goal_fact
        comp_of, stop, low_bits, shift = self.comp_of, self.goal_stop, self._low_bits, self._shift
        buckets: list[list[int]] = [[]]
        top = 0  # highest bucket index in use
        diff = state ^ self.ref
        if diff.bit_count() * self.far > self.n_facts:
            # Far from the reference state: count the state's facts down, firing as they complete.
            cost = self._inf[:]
            x = self._x0[:]
            first = self._facts(state)
            for f in first:
                cost[f] = 0
            for f in first:
                for u in pre_of[f]:
                    n = x[u] + 1
                    x[u] = n
                    if not n & low_bits:
                        v = n >> shift
                        for g in add[u]:
                            if v < cost[g]:
                                cost[g] = v
                                sup[g] = u
                                if g == stop:
                                    return cost, sup
                                if v > top:
                                    buckets.extend([] for _ in range(v - top))
                                    top = v
                                buckets[v].append(g)
        else:
            # Level 0 from the reference state's counters, adjusted for the atoms that differ.
            cost = self._ref_cost[:]
            x = self._ref_x[:]
            extra = []
            while diff:
                low = diff & -diff
                diff ^= low
                a = low.bit_length() - 1
                c_a = comp_of[a]
                on, off = (a, c_a) if state & low else (c_a, a)
                if on >= 0:
                    cost[on] = 0
                    for u in pre_of[on]:
                        n = x[u] + 1
                        x[u] = n
                        if not n & low_bits:
                            extra.append(u)
                if off >= 0:
                    cost[off] = INF
                    for u in pre_of[off]:
                        x[u] -= 1
            # Enabled operators fire in the order a fact-by-fact count fires them (see _rank).
            enabled = self._ref_zero
            if extra:
                enabled = sorted({*enabled, *extra}, key=self._rank.__getitem__)
            for u in enabled:
                n = x[u]
                if n & low_bits:
                    continue
                v = n >> shift
                for g in add[u]:
                    if v < cost[g]:
                        cost[g] = v
                        sup[g] = u
                        if g == stop:
                            return cost, sup
                        if v > top:
                            buckets.extend([] for _ in range(v - top))
                            top = v
                        buckets[v].append(g)
        # Facts reached at cost 0 (zero-cost operators) still belong to level 0; the bucket being
        # iterated may grow.
        for f in buckets[0]:
            if f == goal:
                return cost, sup
            for u in pre_of[f]:
                n = x[u] + 1
                x[u] = n
                if not n & low_bits:
                    v = n >> shift
                    for g in add[u]:
                        if v < cost[g]:
                            cost[g] = v
                            sup[g] = u
                            if g == stop:
                                return cost, sup
                            if v > top:
                                buckets.extend([] for _ in range(v - top))
                                top = v
                            buckets[v].append(g)
        c = 1
        lifo = self._lifo
        while c <= top:
            step = (c << shift) + 1
            bucket = buckets[c]
            # FIFO (the compiled kernels' order) or, with ``lifo``, last in first out as Fast
            # Downward's bucket queue pops: same costs, other best supporters among equal ones.
            for f in _drain(bucket) if lifo else bucket:
                if cost[f] != c:
                    continue
                if f == goal:
                    return cost, sup
                for u in pre_of[f]:
                    n = x[u] + step
                    x[u] = n
                    if n & low_bits:
                        continue
                    v = n >> shift
                    for g in add[u]:
                        if v < cost[g]:
                            cost[g] = v
                            sup[g] = u
                            if g == stop:
                                return cost, sup
                            if v > top:
                                buckets.extend([] for _ in range(v - top))
                                top = v
                            buckets[v].append(g)
            c += 1
        return cost, sup

    @property
    def achievers(self) -> list[list[int]]:
        """The unary operators adding each fact (LM-cut's backward zone walk)."""
        if self._achievers is None:
            self._achievers = [[] for _ in range(self.n_facts)]
            for u, a in enumerate(self.add):
                for f in a:
                    self._achievers[f].append(u)
        return self._achievers

    def ff(self, state: int, applicable: list[int] | None = None) -> tuple[float, list[int]]:
        """FF heuristic (relaxed plan from h_add supporters) and the preferred operators it suggests
        (``applicable``: the state's applicable operators, when the caller has them)."""
        task = self.task
        pre_mask, neg_mask = task.pre_mask, task.neg_mask
        jit = self._jit
        if jit is not None:
            if self._jit_ff is not None:  # the C kernels: h and the preferred operators in one call
                found = self._jit_ff(state)
                return (INF, []) if found is None else found
            plan = jit.ff_plan(state)
            if plan is None:
                return INF, []
            h = len(plan) if self.unit else sum(task.ops[o].cost for o in plan)
            if applicable is not None and len(applicable) < len(plan):
                in_plan = set(plan)
                return h, [o for o in applicable if o in in_plan]
            return h, sorted(
                o for o in plan if state & pre_mask[o] == pre_mask[o] and not state & neg_mask[o]
            )
        if self._jit_open:
            if self._py_time > self._jit_check:
                # Wall time is cheap to read (process_time costs ~20 us here) but counts other
                # processes' load: confirm with this process's CPU time since construction.
                # The CPU threshold is the stage's own (C_AFTER, then JIT_AFTER for numba), not the
                # wall-time check point: under load wall time runs ahead of CPU time, and comparing
                # CPU with the moving check point never switched (logistics00 14-1 at load 12: 1.06 s
                # of wall in Python h_FF, 0.37 s CPU in all, never compiled).
                stage = self._jit_stage
                if process_time() - self._cpu0 > stage:
                    self._use_jit(numba=stage >= relax_jit.JIT_AFTER)
                    if self._jit is not None:
                        return self.ff(state, applicable)
                    # no C kernels: numba once the search has taken JIT_AFTER
                    self._jit_stage = self._jit_check = relax_jit.JIT_AFTER
                else:
                    self._jit_check += stage
            start = perf_counter()
            found = self._ff_python(state)
            self._py_time += perf_counter() - start
            return found
        return self._ff_python(state)

    def _ff_python(self, state: int) -> tuple[float, list[int]]:
        task = self.task
        pre_mask, neg_mask = task.pre_mask, task.neg_mask
        cost, sup = self.hadd(state)
        if cost[self.goal_fact] == INF:
            return INF, []
        ops: set[int] = set()
        seen = {self.goal_fact}
        stack = [self.goal_fact]
        pre, owner = self.pre, self.owner
        while stack:
            u = sup[stack.pop()]
            if u < 0:
                continue
            if owner[u] >= 0:
                ops.add(owner[u])
            for g in pre[u]:
                if g not in seen:
                    seen.add(g)
                    stack.append(g)
        h = len(ops) if self.unit else sum(task.ops[o].cost for o in ops)
        # ascending, as every backend returns them (the searches only test membership)
        preferred = sorted(o for o in ops if state & pre_mask[o] == pre_mask[o] and not state & neg_mask[o])
        return h, preferred

    def hmax(self, state: int, cost_of: list[float] | None = None) -> tuple[list[float], list[int]]:
        """h_max costs of all facts and each enabled unary operator's critical precondition (-1 if none)."""
        base = self.cost if cost_of is None else cost_of
        cost = self._inf[:]
        unsat = self.npre[:]
        pcf = [-1] * len(self.pre)
        pre_of, add = self.pre_of, self.add
        heap = self._start(state)
        for _, f in heap:
            cost[f] = 0
        while heap:
            c, f = heappop(heap)
            if c > cost[f]:
                continue
            for u in pre_of[f]:
                unsat[u] -= 1
                if not unsat[u]:
                    # Facts are settled in cost order, so the last precondition is the costliest.
                    pcf[u] = f
                    v = c + base[u]
                    for g in add[u]:
                        if v < cost[g]:
                            cost[g] = v
                            heappush(heap, (v, g))
        return cost, pcf

    def hmax_value(self, state: int) -> float:
        """The h_max estimate of the goal."""
        return self.hmax(state)[0][self.goal_fact]

    def lmcut(self, state: int) -> float:
        """LM-cut (Helmert & Domshlak 2009): admissible for tasks without conditional effects."""
        costs = list(self.cost)
        goal, add, achievers = self.goal_fact, self.add, self.achievers
        h = 0.0
        while True:
            fact_cost, pcf = self.hmax(state, costs)
            if fact_cost[goal] == INF:
                return INF
            if fact_cost[goal] == 0:
                return h
            zone = {goal}
            stack = [goal]
            while stack:
                f = stack.pop()
                for u in achievers[f]:
                    p = pcf[u]
                    if p >= 0 and costs[u] == 0 and p not in zone:
                        zone.add(p)
                        stack.append(p)
            by_pcf: dict[int, list[int]] = {}
            for u, p in enumerate(pcf):
                if p >= 0:
                    by_pcf.setdefault(p, []).append(u)
            reached = {f for _, f in self._start(state)}
            stack = list(reached)
            cut: set[int] = set()
            while stack:
                f = stack.pop()
                for u in by_pcf.get(f, ()):
                    for g in add[u]:
                        if g in zone:
                            cut.add(u)
                        elif g not in reached:
                            reached.add(g)
                            stack.append(g)
            m = min(costs[u] for u in cut)
            h += m
            for u in cut:
                costs[u] -= m
