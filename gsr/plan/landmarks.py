"""Landmarks by backchaining (LAMA's RHW landmarks, simplified) and the landmark-count heuristic.

Facts are *extended*: every ground atom, and a complement fact "not a" for each atom that occurs
negatively (operator and effect-condition preconditions, goals), true in a state without ``a`` and
achieved by every operator that deletes ``a`` (the same complements as the relaxation's, see
``gsr.plan.heuristics``). A landmark is a fact, or a disjunction of facts, that every plan makes
true at some point. The goal facts are landmarks; going backwards, for each landmark not initially
true its *first achievers* are the operators (one relaxed operator per operator and per conditional
effect) adding it that are applicable in the delete relaxation before the landmark is reached:

- the preconditions shared by every first achiever are landmarks, ordered before it
  (greedy-necessary orderings; Zhu & Givan 2003, Richter, Helmert & Westphal 2008);
- with ``disjunctive=True``, the preconditions of one predicate, not initially true, of which
  every first achiever has one, form a disjunctive landmark when they are 2-4 facts, none is a
  single-fact landmark and none is in another disjunctive landmark (RHW's overlap rule: visitall's
  neighbouring cells would otherwise give one overlapping disjunction per cell); e.g. "one of the
  two keys is held". Off by default: measured mixed on the dev sets (lama, expansions without ->
  with them: elevators-sat08 p23 1,271 -> 605, transport-sat08 p16 3,808 -> 2,432, but satellite
  p19 857 -> 3,692, visitall problem32 3,526 -> 7,534, rovers p31 1,658 -> 2,346).

Complements make "the cell must be cleared first" a landmark (tidybot: an object standing on
another's goal cell must be picked up first; with them and "required again" below, lama solves
tidybot-sat11 p13 in 1,841 expansions, none in 60 s before). No domain-transition-graph step and no
reasonable orders (LAMA has both).

The landmark-count heuristic is path-dependent: a landmark is *accepted* when it holds in a state
reached on the path and all landmarks ordered before it were accepted earlier; h counts the
landmarks not accepted, plus the accepted landmarks that are false again and still needed (goal
landmarks, and landmarks ordered before one not accepted yet, LAMA's "required again"). Its
preferred operators add a landmark whose predecessors are accepted.
"""

from __future__ import annotations

from time import perf_counter

from gsr.plan import relax_jit
from gsr.plan.landmarks_mutex import MutexGroups
from gsr.plan.landmarks_orders import Orders
from gsr.plan.task import Task, bits

MAX_DISJUNCTION = 4  # RHW's limit on disjunctive landmarks
REQUIRED_AGAIN = True  # count accepted landmarks that are false again and still needed
REASONABLE = True  # natural, reasonable and obedient-reasonable orders (landmarks_orders)


class Landmarks:
    """The landmark graph of a task over extended facts and the landmark-count heuristic.

    Extended fact ids: ``0 .. n-1`` the atoms, ``n + j`` the complement of atom ``negated[j]``.
    Landmark ``k`` is the disjunction ``lm_facts[k]``; it holds in a state when one of its atoms
    (``pos_mask[k]``) is true or one of its complemented atoms (``neg_mask[k]``) is false.
    """

    def __init__(
        self,
        task: Task,
        limit: int = 2000,
        disjunctive: bool = False,
        reasonable: bool = REASONABLE,
        mutexes: MutexGroups | None = None,
    ) -> None:
        """``disjunctive``: also RHW's disjunctive landmarks (off by default: measured mixed, see
        the module docstring); ``reasonable``: natural, reasonable and obedient-reasonable orders
        (``gsr.plan.landmarks_orders``); ``mutexes``: the task's mutex groups when the caller has
        them (another graph's ``orders.mutexes``), else found here when the orders need them."""
        build_start = perf_counter()
        self.task = task
        n = self.n_atoms = len(task.atoms)
        self.lm_facts: list[tuple[int, ...]] = []  # landmark index -> extended fact ids
        self.parents: list[int] = []  # landmark index -> bitmask of landmarks ordered before it
        self.goal_mask = 0  # landmark indices that are goals
        self._py_time = 0.0  # seconds of Python exploration (then the compiled one takes over)
        self._compiled = None  # relax_c.CReach or relax_jit.CompiledReach once compiled
        self._compile_after = relax_jit.C_AFTER  # seconds of Python exploration before compiling
        derived = task.derived_mask
        conds = {id(o.cond): o.cond for o in task.ops}.values()
        self.negated = sorted(
            (
                {a for o in (*task.ops, *task.axioms) for a in o.neg}
                | {a for cond in conds for _cp, cn, _ca, _cd in cond for a in cn}
                | {a for _p, ng in task.goals for a in ng}
            )
            - {a for a in range(n) if derived >> a & 1}
        )
        self.comp = {a: n + j for j, a in enumerate(self.negated)}
        self.n_ext = n + len(self.negated)
        self._build_unary()
        index: dict[tuple[int, ...], int] = {}  # landmark facts -> landmark index
        simple: dict[int, int] = {}  # extended fact -> its single-fact landmark
        order: dict[int, set[int]] = {}  # landmark -> landmarks ordered before it
        todo: list[int] = []
        later: list[tuple[tuple[int, ...], int]] = []  # disjunctive candidates, after the simple ones
        reach: dict[int, int] = {}  # landmark -> extended facts reachable without it
        in_disjunction: set[int] = set()  # facts of the disjunctive landmarks

        def add(facts: tuple[int, ...]) -> int:
            k = index.get(facts)
            if k is None:
                k = index[facts] = len(self.lm_facts)
                self.lm_facts.append(facts)
                if len(facts) == 1:
                    simple[facts[0]] = k
                todo.append(k)
            return k

        if len(task.goals) == 1:  # a disjunctive goal: no fact is a landmark for sure
            pos, neg = task.goals[0]
            for g in (*pos, *(self.comp[a] for a in neg if a in self.comp)):
                if g < n and derived >> g & 1:
                    continue
                self.goal_mask |= 1 << add((g,))
        init_ext = self._init_ext
        adders = self._adders
        while (todo or later) and len(self.lm_facts) < limit:
            if not todo:
                facts, after = later.pop(0)
                if facts in index:
                    order.setdefault(after, set()).add(index[facts])
                elif not any(f in simple or f in in_disjunction for f in facts):
                    k = add(facts)
                    order.setdefault(after, set()).add(k)
                    in_disjunction.update(facts)
                continue
            k = todo.pop()
            facts = self.lm_facts[k]
            if any(init_ext >> f & 1 for f in facts):
                continue  # true at the start: nothing needs to precede it
            reached = self._reached_without(facts)
            reach[k] = reached
            pre_ext = self._pre_ext
            first = [u for f in facts for u in adders.get(f, ()) if reached & pre_ext[u] == pre_ext[u]]
            if not first:
                continue
            shared = set(self._pre[first[0]])
            for u in first[1:]:
                shared &= set(self._pre[u])
                if not shared:
                    break
            for p in sorted(shared):
                if p < n and derived >> p & 1:
                    continue
                order.setdefault(k, set()).add(add((p,)))
            # Disjunctive landmarks: per predicate, the preconditions not initially true.
            groups: dict[str, set[int]] = {}
            users: dict[str, int] = {}
            for u in first:
                seen_here = set()
                for p in self._pre[u]:
                    if p >= n or init_ext >> p & 1 or derived >> p & 1:
                        continue
                    name = task.atoms[p].predicate
                    groups.setdefault(name, set()).add(p)
                    if name not in seen_here:
                        seen_here.add(name)
                        users[name] = users.get(name, 0) + 1
            for name, group in groups.items() if disjunctive else ():
                if users[name] == len(first) and 1 < len(group) <= MAX_DISJUNCTION:
                    later.append((tuple(sorted(group)), k))
        m = len(self.lm_facts)
        self.gn_parents = [0] * m  # greedy-necessary orders: "required again" follows these
        for k, before in order.items():
            for p in before:
                if p != k:
                    self.gn_parents[k] |= 1 << p
        self.parents = self.gn_parents  # orders a landmark's acceptance waits for
        self.orders: Orders | None = None
        if reasonable and m > 1:
            self.orders = Orders(
                task,
                self.lm_facts,
                self.negated,
                self.gn_parents,
                self.goal_mask,
                self._init_ext,
                reach,
                MutexGroups(task) if mutexes is None else mutexes,
            )
            self.parents = self.orders.accept_parents
        self.build_time = perf_counter() - build_start
        self.pos_mask = [0] * m
        self.neg_mask = [0] * m
        self.by_pos: dict[int, list[int]] = {}
        self.by_neg: dict[int, list[int]] = {}
        for k, facts in enumerate(self.lm_facts):
            for f in facts:
                if f < n:
                    self.pos_mask[k] |= 1 << f
                    self.by_pos.setdefault(f, []).append(k)
                else:
                    a = self.negated[f - n]
                    self.neg_mask[k] |= 1 << a
                    self.by_neg.setdefault(a, []).append(k)
        self.all_mask = (1 << m) - 1
        self.pos_union = sum(1 << a for a in self.by_pos)
        self.neg_union = sum(1 << a for a in self.by_neg)
        # Atoms of several landmarks are never masked out as "done" (see accept).
        self._shared_pos = sum(1 << a for a, ks in self.by_pos.items() if len(ks) > 1)
        self._shared_neg = sum(1 << a for a, ks in self.by_neg.items() if len(ks) > 1)
        self.goal_lms = list(bits(self.goal_mask))
        self.lm_adds: dict[int, list[int]] = {}  # operator -> the landmarks it adds
        self.lm_add_mask: dict[int, int] = {}  # operator -> bitmask of the landmarks it adds
        for k, facts in enumerate(self.lm_facts):
            for f in facts:
                for u in adders.get(f, ()):
                    i = self._owner[u]
                    if not self.lm_add_mask.get(i, 0) >> k & 1:
                        self.lm_adds.setdefault(i, []).append(k)
                        self.lm_add_mask[i] = self.lm_add_mask.get(i, 0) | 1 << k
        # Per accepted set (a path-dependent value shared by many states): the atoms of its
        # landmarks, the landmarks ready next (not accepted, every predecessor accepted) and the
        # accepted ones still needed (goals and predecessors of landmarks not accepted).
        self._done: dict[int, tuple[int, int]] = {}
        self._ready: dict[int, tuple[int, int]] = {}
        self._unary = None  # exploration tables are only needed while the graph is built
        self._pre = self._pre_ext = None

    @property
    def facts(self) -> list[tuple[int, ...]]:
        """Landmark index -> its extended fact ids (a disjunction)."""
        return self.lm_facts

    def describe(self, k: int) -> str:
        """Landmark ``k`` as text: ``(at x c)``, ``(not (clear a))``, ``(on a b) | (on a c)``."""
        n = self.n_atoms
        return " | ".join(
            str(self.task.atoms[f]) if f < n else f"(not {self.task.atoms[self.negated[f - n]]})"
            for f in self.lm_facts[k]
        )

    def holds(self, k: int, state: int) -> bool:
        """True when landmark ``k`` holds in ``state``."""
        return bool(state & self.pos_mask[k] or self.neg_mask[k] & ~state)

    def _build_unary(self) -> None:
        """One relaxed operator per operator (its precondition facts, its added facts: adds and the
        complements of its deletes) and one per conditional effect (precondition plus condition)."""
        task, comp = self.task, self.comp
        pre_of: dict[int, list[int]] = {}
        adds: list[tuple[int, ...]] = []
        npre: list[int] = []
        pres_of: list[tuple[int, ...]] = []
        owner: list[int] = []
        adders: dict[int, list[int]] = {}
        for i, o in enumerate(task.ops):
            base = (*o.pre, *(comp[a] for a in o.neg if a in comp))
            parts = [(base, (*o.add, *(comp[d] for d in o.delete if d in comp)))]
            for cp, cn, ca, cd in o.cond:
                parts.append(
                    (
                        (*base, *cp, *(comp[a] for a in cn if a in comp)),
                        (*ca, *(comp[d] for d in cd if d in comp)),
                    )
                )
            for pre, add in parts:
                if not add:
                    continue
                u = len(adds)
                pres = tuple(sorted(set(pre)))
                for p in pres:
                    pre_of.setdefault(p, []).append(u)
                adds.append(tuple(add))
                for f in set(add):
                    adders.setdefault(f, []).append(u)
                npre.append(len(pres))
                pres_of.append(pres)
                owner.append(i)
        init = task.init
        self._init_ext = init | sum(1 << c for a, c in comp.items() if not init >> a & 1)
        self._unary = (pre_of, adds, npre, [u for u, k in enumerate(npre) if not k])
        self._pre = pres_of
        self._pre_ext = [sum(1 << p for p in pres) for pres in pres_of]
        self._owner = owner
        self._adders = adders

    def _reached_without(self, facts: tuple[int, ...]) -> int:
        """The extended facts reached in the delete relaxation when ``facts`` are never added (all
        facts when the task has axioms: derived preconditions do not prune achievers)."""
        if self.task.axioms:
            return -1  # every bit set
        pre_of, adds, npre, no_pre = self._unary
        if self._compiled is not None:
            return self._compiled.reached(facts)
        start = perf_counter()
        # Counter-based exploration (each precondition edge visited once, as in FF's h_add).
        unsat = npre[:]
        seen = bytearray(self.n_ext)
        for f in facts:
            seen[f] = 1  # never added
        queue = [f for f in bits(self._init_ext) if not seen[f]]
        for f in queue:
            seen[f] = 1
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
            numba = check >= relax_jit.JIT_AFTER
            self._compiled = relax_jit.compiled_reach(
                self.n_ext, bits(self._init_ext), pre_of, adds, npre, no_pre, numba
            )
            if self._compiled is None:
                self._compile_after = relax_jit.JIT_AFTER if not numba else float("inf")
        return reached

    def accept(self, accepted: int, state: int) -> int:
        """The accepted landmarks after reaching ``state`` (``accepted``: those of its parent)."""
        if not self.lm_facts:
            return 0
        # Candidates: landmarks true in the state and not accepted yet (usually none or a handful),
        # found on the atoms: the accepted landmarks' atoms are masked out first.
        done = self._done.get(accepted)
        if done is None:
            dp = dn = 0
            for k in bits(accepted):
                dp |= self.pos_mask[k]
                dn |= self.neg_mask[k]
            done = self._done[accepted] = (dp & ~self._shared_pos, dn & ~self._shared_neg)
        fresh_pos = state & self.pos_union & ~done[0]
        fresh_neg = self.neg_union & ~state & ~done[1]
        if not fresh_pos and not fresh_neg:
            return accepted
        todo = set()
        if fresh_pos:
            by_pos = self.by_pos
            for a in bits(fresh_pos):
                todo.update(by_pos[a])
        if fresh_neg:
            by_neg = self.by_neg
            for a in bits(fresh_neg):
                todo.update(by_neg[a])
        todo = sorted(k for k in todo if not accepted >> k & 1)
        parents = self.parents
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

    def _ready_needed(self, accepted: int) -> tuple[int, int, int, list[int]]:
        """Per accepted set: the landmarks ready next, and the accepted ones still required, as the
        atoms of the single-fact ones (positive, complemented) and the list of the disjunctive ones
        (a single-fact landmark owns its atom, so "false again" is one mask test per state)."""
        found = self._ready.get(accepted)
        if found is None:
            parents, gn_parents = self.parents, self.gn_parents
            ready = needed = 0
            for k in bits(self.all_mask & ~accepted):
                needed |= gn_parents[k]
                if accepted & parents[k] == parents[k]:
                    ready |= 1 << k
            if not REQUIRED_AGAIN:
                needed = 0
            pos = neg = 0
            disjunctive = []
            for k in bits((needed | self.goal_mask) & accepted):
                if len(self.lm_facts[k]) > 1:
                    disjunctive.append(k)
                else:
                    pos |= self.pos_mask[k]
                    neg |= self.neg_mask[k]
            found = self._ready[accepted] = (ready, pos, neg, disjunctive)
        return found

    def value(
        self,
        accepted: int,
        state: int,
        applicable: list[int] | None = None,
        adds: dict[int, int] | None = None,
    ) -> tuple[int, list[int]]:
        """Landmark count of a state with its accepted landmarks, and the preferred operators
        (``applicable``: the state's applicable operators, when the caller has them; ``adds``: the
        operators' landmark masks that make them preferred, ``lm_add_mask`` by default, e.g.
        ``single_fact_adds()``)."""
        if not self.lm_facts:
            return 0, []
        h = (self.all_mask & ~accepted).bit_count()
        ready, pos, neg, disjunctive = self._ready_needed(accepted)
        # Required again: accepted, still needed, and false in the state.
        h += (pos & ~state).bit_count() + (neg & state).bit_count()
        if disjunctive:
            pos_mask, neg_mask = self.pos_mask, self.neg_mask
            for k in disjunctive:
                if not (state & pos_mask[k] or neg_mask[k] & ~state):
                    h += 1
        # Preferred: applicable operators adding a landmark not accepted whose predecessors are.
        if not ready:
            return h, []
        if applicable is None:
            applicable = self.task.applicable(state)
        if adds is None:
            adds = self.lm_add_mask
        return h, [i for i in applicable if adds.get(i, 0) & ready]

    def goals_only(self) -> bool:
        """True when every landmark is a goal fact and none is ordered before another: the landmark
        count is then the number of goals not reached (issue 18, eighth pass: ``lama`` then tries
        the disjunctive landmarks)."""
        return bool(self.lm_facts) and self.goal_mask == self.all_mask and not any(self.gn_parents)

    def single_fact_adds(self) -> dict[int, int]:
        """``lm_add_mask`` restricted to the single-fact landmarks: the disjunctive ones' achievers
        are then not landmark-preferred (``LamaOptions.lm_preferred_disjunctive``)."""
        single = sum(1 << k for k, facts in enumerate(self.lm_facts) if len(facts) == 1)
        return {i: m & single for i, m in self.lm_add_mask.items() if m & single}
