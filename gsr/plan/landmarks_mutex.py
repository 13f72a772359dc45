"""Mutex groups of a ground task: sets of atoms of which at most one is true in every reachable state.

The landmark graph's reasonable orders need to know which facts cannot hold together (Hoffmann,
Porteous & Sebastia 2004's interference), and Fast Downward reads that from the finite-domain
variables its translator's invariant synthesis finds. This module finds the same kind of invariant
on the ground operators, without a lifted prover:

- A *signature* ``(predicate, key positions)`` names, for each atom of the predicate, its *key*: the
  arguments at those positions, in that order (``(on ?x ?y)`` with key position 1: the block below).
  The positions left out are the invariant's counted argument. A *candidate* is a set of
  signatures of distinct predicates with keys of one length (``clear``[0], ``on``[1],
  ``holding``[0]: "per block, at most one of clear, something on it, held").
- A candidate is an invariant when the initial state has at most one of its atoms per key and every
  operator that adds one of its atoms (not already required true) also deletes one of the same key
  that its precondition requires (an unconditional add against an unconditional delete, a
  conditional add against a delete of the same effect or an unconditional one), and adds no two of
  one key. Induction on the plan length then gives "at most one per key" in every reachable state.
- Candidates start from single signatures (any set of counted arguments) and grow as in Fast
  Downward's invariant synthesis: when an operator adds an atom of the key with no balancing delete,
  each signature of a deleted precondition atom carrying the same key is tried as an addition.

Each key of an invariant gives a *group*: its atoms with that key (groups of one atom are dropped).
A group is *exactly-one* (a finite-domain variable) when the initial state has one of its atoms and
every operator deleting one of them, as a precondition, adds another of the same key.
"""

from __future__ import annotations

from itertools import combinations, permutations

from gsr.plan.task import Task

MAX_SIGNATURES = 5  # largest candidate tried (Fast Downward's invariants rarely exceed four parts)
MAX_CANDIDATES = 400  # candidates checked per task
#: Checking work at most per task, counted as atoms keyed plus operators checked over all candidates
#: (a few microseconds each: 600,000 is 2-3.5 CPU-s on the development machine; the largest dev
#: problems need 520,000 (tidybot-sat11 p19) to 1,000,000 (satellite p33)). A budget in work, not
#: seconds, so that the groups found (and the landmark orders built on them) do not depend on the
#: machine or its load.
MAX_WORK = 600_000


class MutexGroups:
    """The mutex groups of a task's atoms (derived atoms and static ones left out).

    ``groups[g]`` is a tuple of atom ids, at most one true in any reachable state; ``exactly_one[g]``
    says exactly one is; ``of_atom[a]`` the groups holding atom ``a``.
    """

    def __init__(self, task: Task, max_work: int = MAX_WORK) -> None:
        """``max_work``: checking work at most (large tasks keep the invariants found by then)."""
        self.task = task
        self.groups: list[tuple[int, ...]] = []
        self.exactly_one: list[bool] = []
        self.of_atom: dict[int, frozenset[int]] = {}
        self.invariants: list[tuple[tuple[str, tuple[int, ...]], ...]] = []
        self.work = 0  # atoms keyed + operators checked so far
        self.complete = True  # False when the work budget cut the search short
        self._max_work = max_work
        atoms = task.atoms
        derived = task.derived_mask
        changing = set()
        for o in task.ops:
            changing.update(o.add)
            changing.update(o.delete)
            for _cp, _cn, ca, cd in o.cond:
                changing.update(ca)
                changing.update(cd)
        self._fluent_preds = {atoms[a].predicate for a in changing if not derived >> a & 1}
        self._by_pred: dict[str, list[int]] = {}
        for a, atom in enumerate(atoms):
            if atom.predicate in self._fluent_preds and not derived >> a & 1:
                self._by_pred.setdefault(atom.predicate, []).append(a)
        # Operators (with their conditional effects as separate parts) indexed by added predicate.
        self._adding: dict[str, list[int]] = {}
        self._deleting: dict[str, list[int]] = {}
        for i, o in enumerate(task.ops):
            preds = {atoms[a].predicate for a in o.add}
            for _cp, _cn, ca, _cd in o.cond:
                preds.update(atoms[a].predicate for a in ca)
            for p in preds:
                self._adding.setdefault(p, []).append(i)
            dels = {atoms[a].predicate for a in o.delete}
            for _cp, _cn, _ca, cd in o.cond:
                dels.update(atoms[a].predicate for a in cd)
            for p in dels:
                self._deleting.setdefault(p, []).append(i)
        self._find()

    def mutex(self, a: int, b: int) -> bool:
        """True when atoms ``a`` and ``b`` (distinct) are never true together."""
        ga = self.of_atom.get(a)
        gb = self.of_atom.get(b)
        return a != b and ga is not None and gb is not None and not ga.isdisjoint(gb)

    # -- invariant synthesis --------------------------------------------------------------------

    def _key(self, a: int, positions: tuple[int, ...]) -> tuple[str, ...]:
        args = self.task.atoms[a].args
        return tuple(args[i] for i in positions)

    def _find(self) -> None:
        atoms = self.task.atoms
        start: list[frozenset] = []
        for pred, ids in self._by_pred.items():
            arity = len(atoms[ids[0]].args)
            for size in range(arity, -1, -1):  # fewest counted arguments first
                start.extend(frozenset({(pred, key)}) for key in combinations(range(arity), size))
        seen = set(start)
        queue = list(start)
        found: list[tuple[frozenset, bool]] = []
        checked = 0
        while queue and checked < MAX_CANDIDATES:
            if self.work >= self._max_work:
                self.complete = False
                break
            cand = queue.pop(0)
            checked += 1
            ok, strict, refinements = self._check(cand)
            if ok:
                found.append((cand, strict))
                continue
            if len(cand) >= MAX_SIGNATURES:
                continue
            for sig in refinements:
                bigger = cand | {sig}
                if bigger not in seen:
                    seen.add(bigger)
                    queue.append(bigger)
        groups: dict[tuple[int, ...], bool] = {}
        for cand, strict in found:
            by_key: dict[tuple[str, ...], list[int]] = {}
            for pred, positions in cand:
                for a in self._by_pred[pred]:
                    by_key.setdefault(self._key(a, positions), []).append(a)
            for members in by_key.values():
                if len(members) > 1:
                    g = tuple(sorted(members))
                    exact = strict and sum(self.task.init >> a & 1 for a in g) == 1
                    groups[g] = groups.get(g, False) or exact
            self.invariants.append(tuple(sorted(cand)))
        of_atom: dict[int, set[int]] = {}
        for g, exact in groups.items():
            gid = len(self.groups)
            self.groups.append(g)
            self.exactly_one.append(exact)
            for a in g:
                of_atom.setdefault(a, set()).add(gid)
        self.of_atom = {a: frozenset(gs) for a, gs in of_atom.items()}

    def _check(self, cand: frozenset) -> tuple[bool, bool, list[tuple[str, tuple[int, ...]]]]:
        """(invariant?, strict?, signatures that could repair the first violation)."""
        task = self.task
        atoms = task.atoms
        sig_of = dict(cand)  # predicate -> key positions
        if len(sig_of) < len(cand):
            return False, False, []  # two signatures of one predicate

        keys: dict[int, tuple[str, ...]] = {}  # atom of the candidate -> its key
        for pred, positions in sig_of.items():
            for a in self._by_pred[pred]:
                args = atoms[a].args
                keys[a] = tuple(args[i] for i in positions)
        self.work += len(keys)
        key = keys.get
        init_keys = set()
        for pred in sig_of:
            for a in self._by_pred[pred]:
                if task.init >> a & 1:
                    k = keys[a]
                    if k in init_keys:
                        return False, False, []
                    init_keys.add(k)
        length = len(next(iter(sig_of.values())))
        ops = set()
        for pred in sig_of:
            ops.update(self._adding.get(pred, ()))
        strict = True
        for i in sorted(ops):
            self.work += 1
            o = task.ops[i]
            pre = set(o.pre)
            parts = [(pre, o.add, o.delete, ())]
            for cp, _cn, ca, cd in o.cond:
                parts.append((pre | set(cp), ca, cd, o.delete))
            added: dict[tuple[str, ...], int] = {}
            for part_pre, adds, dels, also_dels in parts:
                for a in adds:
                    k = key(a)
                    if k is None or a in part_pre:
                        continue
                    if k in added and added[k] != a:
                        return False, False, []  # two atoms of one key added
                    added[k] = a
                    if any(d != a and d in part_pre and key(d) == k for d in (*dels, *also_dels)):
                        continue
                    # Repairs: a deleted precondition atom whose arguments carry the key.
                    repairs = []
                    for d in (*dels, *also_dels):
                        if d not in part_pre or atoms[d].predicate in sig_of:
                            continue
                        args = atoms[d].args
                        for positions in permutations(range(len(args)), length):
                            if tuple(args[j] for j in positions) == k:
                                repairs.append((atoms[d].predicate, positions))
                    return False, False, repairs
            if strict:
                # Exactly-one: a deleted precondition atom of the candidate is replaced, same key.
                for d in o.delete:
                    k = key(d)
                    if k is not None and d in pre and k not in added:
                        strict = False
        if strict:
            # Operators that delete an atom of the candidate without adding one were not looked at.
            for pred in sig_of:
                if any(i not in ops for i in self._deleting.get(pred, ())):
                    strict = False
                    break
        return True, strict, []
