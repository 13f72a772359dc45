"""Search algorithms over a ground Task: lazy and eager greedy best-first, A*, breadth-first.

All searches are deterministic (FIFO tie-breaking by insertion counter, operators in id order)
and check the clock every ``CLOCK_EVERY`` expansions.
"""

from __future__ import annotations

import random
import time
from array import array
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from heapq import heappop, heappush, heapreplace

from gsr.plan.heuristics import INF, Relaxation
from gsr.plan.landmarks import Landmarks
from gsr.plan.landmarks_progress import Progression
from gsr.plan.task import Task

CLOCK_EVERY = 64
BOOST = 1000  # Fast Downward's default preferred-operator boost (lama-first)
# Queue entries keep their operators as a packed array of 4-byte ids: a list holds 8-byte pointers
# to int objects of 28 bytes each (the ids past 256 are fresh objects), ~4.5x the memory, and a
# lazy search keeps one entry per expansion until it is popped to its end (driverlog p16: 35,375
# expansions, ~22 successors each).
OP_IDS = "i" if array("i").itemsize == 4 else "l"


def take_next(queue: list) -> tuple[int, int]:
    """Pop the next (parent state id, operator) of a lazy search's queue.

    Each entry holds all successors of one expansion that go into this queue, ``(h, expansion
    number, position, parent, operators)``: the operators share h, and no other expansion's
    operators fall between them in FIFO order, so popping them one by one gives the same order as
    one entry per operator keyed ``(h, insertion counter)`` (Fast Downward's lazy open lists), with
    one heap entry per expansion instead of one per successor. ``operators`` is a list or a packed
    array of operator ids (``OP_IDS``).
    """
    h, c, pos, pid, ops = queue[0]
    if pos + 1 < len(ops):
        heapreplace(queue, (h, c, pos + 1, pid, ops))
    else:
        heappop(queue)
    return pid, ops[pos]


class TypeBuckets:
    """Type-based open list (Xie, Müller, Holte and Imai 2014; Fast Downward's
    ``type_based_open_list.cc``): entries bucketed by a type (a tuple of values); ``pop`` takes a
    uniformly random bucket, then a uniformly random entry of it, so that states of rarely seen
    types get expanded too (exploration out of a heuristic's plateaus). Entries are (parent state
    id, operator) packed into one integer of a per-bucket array; ``random.Random(seed)``: runs
    repeat."""

    __slots__ = ("buckets", "keys", "n_ops", "rng")

    def __init__(self, n_ops: int, seed: int = 0) -> None:
        self.buckets: dict[tuple, array] = {}
        self.keys: list[tuple] = []
        self.n_ops = max(1, n_ops)
        self.rng = random.Random(seed)

    def __len__(self) -> int:
        return len(self.keys)

    def push(self, key: tuple, sid: int, ops) -> None:
        bucket = self.buckets.get(key)
        if bucket is None:
            bucket = self.buckets[key] = array("q")
            self.keys.append(key)
        n = self.n_ops
        base = sid * n
        bucket.extend(base + op for op in ops)

    def pop(self) -> tuple[int, int]:
        keys, rng = self.keys, self.rng
        i = rng.randrange(len(keys))
        key = keys[i]
        bucket = self.buckets[key]
        j = rng.randrange(len(bucket))
        item = bucket[j]
        bucket[j] = bucket[-1]
        bucket.pop()
        if not bucket:
            del self.buckets[key]
            last = keys.pop()
            if i < len(keys):
                keys[i] = last
        return divmod(item, self.n_ops)


@dataclass(slots=True)
class SearchResult:
    """Outcome of one search: status, operator ids and counters."""

    status: str  # "solved" | "unsolvable" | "timeout"
    ops: list[int] = field(default_factory=list)
    expanded: int = 0
    generated: int = 0
    evaluated: int = 0


class _Space:
    """State registry with parent pointers for plan extraction."""

    __slots__ = ("ids", "op", "parent", "states")

    def __init__(self) -> None:
        self.ids: dict[int, int] = {}
        self.states: list[int] = []
        self.parent: list[int] = []
        self.op: list[int] = []

    def add(self, state: int, parent: int, op: int) -> int:
        sid = len(self.states)
        self.ids[state] = sid
        self.states.append(state)
        self.parent.append(parent)
        self.op.append(op)
        return sid

    def path(self, sid: int) -> list[int]:
        out = []
        while self.parent[sid] >= 0:
            out.append(self.op[sid])
            sid = self.parent[sid]
        out.reverse()
        return out


def lazy_gbfs(task: Task, relax: Relaxation, deadline: float) -> SearchResult:
    """Lazy GBFS with h_FF and preferred operators in a boosted dual queue (FD's lazy_greedy)."""
    res = SearchResult("unsolvable")
    space = _Space()
    init = task.init
    root = space.add(init, -1, -1)
    if task.is_goal(init):
        res.status = "solved"
        return res
    open_lists: tuple[list, list] = ([], [])  # (all successors, preferred successors)
    priority = [0, 0]
    counter = 0
    best_h = INF
    apply, is_goal, ff = task.apply, task.is_goal, relax.ff
    pending: tuple[int, int] | None = (root, -1)
    while True:
        if pending is None:
            # Alternation open list: the non-empty queue with the lowest priority counter goes next
            # (the preferred one on ties).
            if open_lists[1] and (not open_lists[0] or priority[1] <= priority[0]):
                which = 1
            elif open_lists[0]:
                which = 0
            else:
                return res
            priority[which] += 1
            pid, op = take_next(open_lists[which])
            state = apply(space.states[pid], op)
            if state in space.ids:
                continue
            sid = space.add(state, pid, op)
            res.generated += 1
            if is_goal(state):
                res.status, res.ops = "solved", space.path(sid)
                return res
        else:
            sid = pending[0]
            state = space.states[sid]
            pending = None
        h, preferred = ff(state)
        res.evaluated += 1
        if h == INF:
            continue
        if h < best_h:
            best_h = h
            priority[1] -= BOOST
        res.expanded += 1
        if not res.expanded % CLOCK_EVERY and time.perf_counter() > deadline:
            res.status = "timeout"
            return res
        # relax.applicable: Task.applicable, or its compiled twin once the relaxation is compiled
        succ_ops = relax.applicable(state)
        if not succ_ops:
            continue
        counter += 1
        heappush(open_lists[0], (h, counter, 0, sid, array(OP_IDS, succ_ops)))
        if preferred:
            pref = set(preferred)
            pref_ops = [op for op in succ_ops if op in pref]
            if pref_ops:
                heappush(open_lists[1], (h, counter, 0, sid, array(OP_IDS, pref_ops)))


def eager_search(
    task: Task, evaluate: Callable[[int], float], deadline: float, weight_g: float, weight_h: float = 1.0
) -> SearchResult:
    """Best-first search on ``weight_g * g + weight_h * h`` with reopening (A* for 1/1, GBFS for 0/1)."""
    res = SearchResult("unsolvable")
    space = _Space()
    init = task.init
    h0 = evaluate(init)
    res.evaluated += 1
    if h0 == INF:
        return res
    root = space.add(init, -1, -1)
    g = [0.0]
    hval = [h0]
    closed = [False]
    heap = [(weight_h * h0, h0, 0, root)]
    counter = 0
    ops, apply, applicable, is_goal = task.ops, task.apply, task.applicable, task.is_goal
    ids, states = space.ids, space.states
    while heap:
        _, _, _, sid = heappop(heap)
        if closed[sid]:
            continue
        closed[sid] = True
        state = states[sid]
        if is_goal(state):
            res.status, res.ops = "solved", space.path(sid)
            return res
        res.expanded += 1
        if not res.expanded % CLOCK_EVERY and time.perf_counter() > deadline:
            res.status = "timeout"
            return res
        gs = g[sid]
        for op in applicable(state):
            succ = apply(state, op)
            res.generated += 1
            ng = gs + ops[op].cost
            tid = ids.get(succ)
            if tid is None:
                h = evaluate(succ)
                res.evaluated += 1
                tid = space.add(succ, sid, op)
                g.append(ng)
                hval.append(h)
                closed.append(False)
                if h == INF:
                    closed[tid] = True
                    continue
            elif ng < g[tid] and weight_g:
                # Cheaper path: reopen (LM-cut and h_max need not be consistent).
                g[tid], space.parent[tid], space.op[tid] = ng, sid, op
                closed[tid] = hval[tid] == INF
                if closed[tid]:
                    continue
            else:
                continue
            counter += 1
            h = hval[tid]
            heappush(heap, (weight_g * g[tid] + weight_h * h, h, counter, tid))
    return res


def breadth_first(task: Task, deadline: float) -> SearchResult:
    """Breadth-first search with duplicate detection (optimal for unit costs)."""
    res = SearchResult("unsolvable")
    space = _Space()
    root = space.add(task.init, -1, -1)
    if task.is_goal(task.init):
        res.status = "solved"
        return res
    queue = deque([root])
    apply, applicable, is_goal, ids = task.apply, task.applicable, task.is_goal, space.ids
    while queue:
        sid = queue.popleft()
        state = space.states[sid]
        res.expanded += 1
        if not res.expanded % CLOCK_EVERY and time.perf_counter() > deadline:
            res.status = "timeout"
            return res
        for op in applicable(state):
            succ = apply(state, op)
            res.generated += 1
            if succ in ids:
                continue
            tid = space.add(succ, sid, op)
            if is_goal(succ):
                res.status, res.ops = "solved", space.path(tid)
                return res
            queue.append(tid)
    return res


@dataclass(frozen=True, slots=True)
class LamaOptions:
    """Switches of ``lazy_lama``; the defaults are GSR's, ``FD_LAMA_FIRST`` is Fast Downward's.

    - ``progression``: ``"accept"`` (``Landmarks.accept``: a landmark counts as reached only after
      its greedy-necessary and reasonable predecessors) or ``"past-future"`` (Fast Downward's
      landmark progression, ``gsr.plan.landmarks_progress``);
    - ``lm_preferred``: the landmark heuristic's preferred operators join h_FF's (FD: no);
    - ``boost_root``: the initial state's values count as progress and boost (FD: no);
    - ``tie_order``: the queues' order on equal priorities, 0 h_FF, 1 h_FF preferred, 2 landmarks,
      3 landmarks preferred (FD's alternation: list order 0, 1, 2, 3).

    - ``dovetail``: 0, or ``share`` of ``dovetail()``: a second search with h_add's other bucket
      order (``Relaxation.lifo``) takes turns with the main one (after ``m`` turns of the main
      search about ``sqrt(dovetail * m)``), so ties between equally cheap supporters no longer
      decide a problem alone (FD: one search).
    - ``lifo``: the main search's h_add settles equally cheap facts last in first out
      (``Relaxation.lifo``, Fast Downward's bucket order); the dovetailed search takes the other
      order. Where the relaxation cannot switch (numba) both keep its order.
    - ``disjunctive``: the landmark graph holds RHW's disjunctive landmarks (the caller builds
      ``Landmarks(task, disjunctive=...)`` from it: ``gsr.plan.api``, ``landmark_profile``).
    - ``lm_preferred_disjunctive``: with ``lm_preferred``, the achievers of disjunctive landmarks
      are preferred too (off: only the single-fact landmarks' achievers are).
    - ``type_based``: a fifth queue in the alternation, ``TypeBuckets`` keyed (h_FF, g) of the
      expanded state (type-based exploration, Xie et al. 2014), never boosted; off (measured on
      transport-sat08 p20: no plan either, docs/performance.md sixth pass).

    Measured (docs/performance.md, issue 18's fifth pass): FD's rules solve neither transport-sat08
    p20 nor tidybot-sat11 p01 and lose transport p19 (and, with FD's tie order, need 14,756
    expansions instead of 2,834 on transport p29), so the defaults stay GSR's. Sixth pass: the
    other bucket order alone solves tidybot p01 (867 expansions) but loses p13 and transport p19;
    dovetailed with GSR's order (``dovetail`` 2) it keeps both. Eighth pass: transport p20 needs
    FD's rules *and* RHW's disjunctive landmarks to be solved within 60 s CPU (LIFO, either alone:
    no plan after 114,752 expansions / 111,560 expansions, 71.5 s search CPU); with both,
    ``lifo`` and GSR's tie order, dovetailed, ``lama`` solves p20 (43.9 s CPU) and transport whole
    in 0.71x the CPU, but loses tidybot p19 and satellite p36-HC, so the defaults stay. What
    planner ``lama`` runs since: these rules (``GOALS_ONLY_LAMA``) only where GSR's landmark graph is
    goals only and the disjunctive landmarks add some (``gsr.plan.api.lama``), ``LAMA_FIRST``
    elsewhere: transport whole 30 / 29 and the other groups unchanged (docs/performance.md).
    """

    progression: str = "accept"
    lm_preferred: bool = True
    boost_root: bool = True
    tie_order: tuple[int, int, int, int] = (1, 3, 0, 2)
    dovetail: int = 2
    type_based: bool = False
    lifo: bool = False
    disjunctive: bool = False
    lm_preferred_disjunctive: bool = True


LAMA_FIRST = LamaOptions()  # what planner "lama" runs
# What "lama" runs where GSR's landmark graph is goals only and RHW's disjunctive landmarks add some
# (``Landmarks.goals_only``, gsr.plan.api): Fast Downward's progression and preferred operators, no
# initial boost, the disjunctive graph, LIFO main search; GSR's tie order, dovetailed (eighth pass).
GOALS_ONLY_LAMA = LamaOptions(
    progression="past-future", lm_preferred=False, boost_root=False, lifo=True, disjunctive=True
)
FD_LAMA_FIRST = LamaOptions(
    progression="past-future", lm_preferred=False, boost_root=False, tie_order=(0, 1, 2, 3), dovetail=0
)


def lazy_lama(
    task: Task,
    relax: Relaxation,
    landmarks: Landmarks,
    deadline: float,
    options: LamaOptions = LAMA_FIRST,
    trace: list | None = None,
) -> SearchResult:
    """LAMA's first iteration (Fast Downward's lama-first): lazy greedy search alternating four
    queues, h_FF and the landmark heuristic, each with all successors and with preferred successors
    only, preferred queues boosted by 1000 when either heuristic reaches a new best value (the
    details are ``LamaOptions``). The landmark status of a state is the one of the path that first
    reached it. ``trace``: a list that receives ``(expansions, "ff" | "lm", value)`` at every new
    best value (of the main search only).

    With ``options.dovetail`` > 0 a second, independent search of the same kind runs beside the
    main one, its h_add settling equally cheap facts in the other bucket order (``Relaxation.lifo``
    flipped, so other best supporters, relaxed plans and preferred operators): the two take turns of
    ``CLOCK_EVERY`` expansions, the second's share shrinking as the search grows (``dovetail``);
    the first to finish gives the result (a plan, or unsolvable: both search the same state space
    completely). They share the task, the relaxation and the landmark graph, not their state
    spaces; the counters are the sum of both. Where the relaxation cannot switch (numba's kernels
    know one order) the main search runs alone."""
    if options.lifo != relax.lifo:
        before = relax.lifo
        try:
            relax.lifo = options.lifo
        except ValueError:  # numba's kernels know one order: keep it
            options = replace(options, lifo=before)
        try:
            return lazy_lama(task, relax, landmarks, deadline, options, trace)
        finally:
            relax.lifo = before
    main_res = SearchResult("unsolvable")
    main = _lama_steps(task, relax, landmarks, deadline, options, trace, main_res)
    if options.dovetail <= 0:
        for _ in main:
            pass
        return main_res
    own = relax.lifo
    other_res = SearchResult("unsolvable")
    other = _lama_steps(task, relax, landmarks, deadline, options, None, other_res)

    def to_main() -> None:
        if relax.lifo != own:
            relax.lifo = own

    def to_other() -> None:
        relax.lifo = not own

    try:
        first = dovetail(main, other, options.dovetail, to_main, to_other)
    finally:
        to_main()
    res = main_res if first == 0 else other_res
    res.expanded = main_res.expanded + other_res.expanded
    res.generated = main_res.generated + other_res.generated
    res.evaluated = main_res.evaluated + other_res.evaluated
    return res


def dovetail(
    main: Iterator[None],
    other: Iterator[None] | None,
    share: int,
    to_main: Callable[[], None],
    to_other: Callable[[], None],
) -> int:
    """Let two step generators take turns until one is exhausted: 0 when ``main`` finished first,
    1 when ``other`` did. ``other`` takes a turn while its turns ``t`` satisfy ``t * t < share *
    m`` (``m`` the turns ``main`` has had), ``main`` otherwise: after ``m`` turns of ``main``
    ``other`` has had about ``sqrt(share * m)``, a share that shrinks as the search grows (with
    ``share`` 4: 2 of 3 turns at first, 1 in 6 after 100 turns, 1 in 17 after 1,000). ``to_main`` /
    ``to_other`` run before each switch; ``to_other`` raising ValueError (the relaxation cannot
    switch) drops ``other``."""
    done = object()
    turns_main = turns_other = 0
    current = -1
    while True:
        if other is not None and turns_other * turns_other < share * turns_main:
            if current != 1:
                try:
                    to_other()
                except ValueError:
                    other = None
                    continue
                current = 1
            turns_other += 1
            if next(other, done) is done:
                return 1
        else:
            if current != 0:
                to_main()
                current = 0
            turns_main += 1
            if next(main, done) is done:
                return 0


def _lama_steps(
    task: Task,
    relax: Relaxation,
    landmarks: Landmarks,
    deadline: float,
    options: LamaOptions,
    trace: list | None,
    res: SearchResult,
) -> Iterator[None]:
    """``lazy_lama``'s search as a generator that fills ``res`` and yields after every
    ``CLOCK_EVERY`` expansions (so that two searches can take turns)."""
    space = _Space()
    init = task.init
    root = space.add(init, -1, -1)
    if options.progression == "past-future":
        prog = Progression(landmarks)
        status = [prog.initial(init)]
        progress, lm_value = prog.progress, prog.value
    elif options.progression == "accept":
        prog = None
        status = [landmarks.accept(0, init)]
        progress = landmarks.accept
    else:
        raise ValueError(f"unknown landmark progression {options.progression!r}")
    if task.is_goal(init):
        res.status = "solved"
        return
    queues: tuple = ([], [], [], [])  # ff, ff preferred, lm, lm preferred (, type-based)
    priority = [0, 0, 0, 0, 0]
    tie_order = options.tie_order
    typed = TypeBuckets(len(task.ops)) if options.type_based else None
    depth = [0]  # g (steps from the start) of each state, the type-based queue's second key
    if typed is not None:
        queues += (typed,)
        tie_order = (*tie_order, 4)
    q_ff, q_ff_pref, q_lm, q_lm_pref = queues[:4]
    counter = 0
    best = [INF, INF]
    apply, is_goal, ff = task.apply, task.is_goal, relax.ff
    lm_pref = options.lm_preferred
    pref_adds = None if options.lm_preferred_disjunctive else landmarks.single_fact_adds()
    boost = options.boost_root
    pending: int | None = root
    while True:
        if pending is None:
            # The non-empty queue with the lowest priority counter, the first in tie_order on ties.
            which = -1
            for i in tie_order:
                if queues[i] and (which < 0 or priority[i] < priority[which]):
                    which = i
            if which < 0:
                return
            priority[which] += 1
            pid, op = take_next(queues[which]) if which < 4 else typed.pop()
            state = apply(space.states[pid], op)
            if state in space.ids:
                continue
            sid = space.add(state, pid, op)
            status.append(progress(status[pid], state))
            if typed is not None:
                depth.append(depth[pid] + 1)
            res.generated += 1
            if is_goal(state):
                res.status, res.ops = "solved", space.path(sid)
                return
        else:
            sid, pending = pending, None
            state = space.states[sid]
        succ_ops = relax.applicable(state)  # Task.applicable or its compiled twin (same list)
        h_ff, pref_ff = ff(state, succ_ops)
        res.evaluated += 1
        if h_ff == INF:
            continue
        if prog is not None:
            h_lm = lm_value(status[sid])
            if h_lm == INF:
                continue
            pref_lm = prog.preferred(status[sid], succ_ops, pref_adds) if lm_pref else ()
        else:
            h_lm, pref_lm = landmarks.value(status[sid], state, succ_ops, pref_adds)
            if not lm_pref:
                pref_lm = ()
        progressed = False
        if h_ff < best[0]:
            best[0] = h_ff
            progressed = True
            if trace is not None:
                trace.append((res.expanded, "ff", h_ff))
        if h_lm < best[1]:
            best[1] = h_lm
            progressed = True
            if trace is not None:
                trace.append((res.expanded, "lm", h_lm))
        if progressed and boost:
            priority[1] -= BOOST
            priority[3] -= BOOST
        boost = True  # every state after the initial one
        res.expanded += 1
        if not res.expanded % CLOCK_EVERY and time.perf_counter() > deadline:
            res.status = "timeout"
            return
        if not res.expanded % CLOCK_EVERY:
            yield
        if not succ_ops:
            continue
        counter += 1
        packed = array(OP_IDS, succ_ops)  # shared by both queues (read only)
        heappush(q_ff, (h_ff, counter, 0, sid, packed))
        heappush(q_lm, (h_lm, counter, 0, sid, packed))
        if typed is not None:
            typed.push((h_ff, depth[sid]), sid, succ_ops)
        if pref_ff or pref_lm:
            pref = set(pref_ff)
            pref.update(pref_lm)
            pref_ops = [op for op in succ_ops if op in pref]
            if pref_ops:
                packed = array(OP_IDS, pref_ops)
                heappush(q_ff_pref, (h_ff, counter, 0, sid, packed))
                heappush(q_lm_pref, (h_lm, counter, 0, sid, packed))
