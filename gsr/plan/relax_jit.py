"""Compiled h_add / h_FF for large tasks (numba, optional).

The pure-Python bucket h_add in ``gsr.plan.heuristics`` costs ~10-20 ms per state on tasks with
tens of thousands of unary operators (IPC transport, tidybot), which is most of the search time.
This module runs the same computation over flat integer arrays (CSR layout) compiled by numba,
when numba is installed (``pip install numba``, optional extra ``fast``); without it, or on small
tasks where the Python path is already fast (the tabletop domain), nothing changes.

Same results as the Python path: the kernel counts a state's facts from scratch in the same order
(atoms ascending, the always-true fact, then the true complement facts), and its priority queue
pops facts by (cost, insertion order), which is the bucket queue's FIFO order within a cost, so
every fact's cost and best supporter equal ``Relaxation._hadd_buckets``'s (tested).

Two backends compute the same values: the C kernels of ``relax_kernels.c`` (``gsr.plan.relax_c``:
built once with the system's C compiler, loaded with ctypes in milliseconds) when a compiler is
there, otherwise numba (~1.2 s CPU to switch: its import and LLVM set-up). ``compiled(relax)``
picks one; ``GSR_PLAN_CC=0`` leaves only numba.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gsr.plan.relax_arrays import UnaryRelaxation

# Unary-operator edges (sum of precondition counts) from which the compiled path is used; below it
# the Python h_add is fast enough and numba's import (~0.3 s) would dominate. Environment variable
# GSR_PLAN_JIT: "0" never, "1" always (when numba is installed), unset: by size.
MIN_EDGES = 20_000
# Seconds of h_FF in Python after which a smaller relaxation switches to the compiled path (numba's
# import costs ~0.8 s CPU). On the dev sets a search that has taken 0.5 s of h_FF nearly always goes
# on for much longer (satellite p19: 857 evaluations at ~2.6 ms); small searches never pay the import.
JIT_AFTER = 0.5
# With the C kernels (switching costs milliseconds, not numba's ~1.2 s) the compiled path is used
# from the start above C_MIN_EDGES, and below it once Python h_FF has taken C_AFTER seconds. Since
# issue 18's second pass every relaxation starts compiled: on the 30 tabletop-long tasks (792-1,523
# edges) the arrays cost ~1 ms and the median plan() CPU fell from 48 to 33 ms (same plans).
C_MIN_EDGES = 0
C_AFTER = 0.05
UNREACHED = 1 << 62  # the kernel's cost of an unreached fact

_kernels = None  # (hadd, ff) once compiled; False when numba is unavailable


def allowed() -> bool:
    """False when GSR_PLAN_JIT=0 forbids the compiled path."""
    return os.environ.get("GSR_PLAN_JIT", "") != "0"


def wanted(edges: int) -> bool:
    """Whether a relaxation with ``edges`` precondition edges should be compiled from the start."""
    if not allowed():
        return False
    if os.environ.get("GSR_PLAN_JIT", "") == "1" or edges >= MIN_EDGES:
        return True
    return edges >= C_MIN_EDGES and c_library() is not None


def c_library():
    """The C kernels' library (built on first use), or None (no compiler, or forbidden)."""
    from gsr.plan import relax_c

    return relax_c.library() if allowed() else None


def compiled(relax: UnaryRelaxation, numba: bool = True):
    """A compiled twin of ``relax`` (C kernels first, numba when ``numba`` allows), or None."""
    lib = c_library()
    if lib is not None:
        from gsr.plan.relax_c import CRelaxation

        return CRelaxation(relax, lib)
    if numba and kernels() is not None:
        return CompiledRelaxation(relax)
    return None


def compiled_reach(n_atoms: int, init_facts: list[int], pre_of, adds, npre, no_pre, numba: bool = True):
    """Landmarks' compiled exploration (C kernels first, numba when ``numba`` allows), or None."""
    lib = c_library()
    if lib is not None:
        from gsr.plan.relax_c import CReach

        return CReach(lib, n_atoms, init_facts, pre_of, adds, npre, no_pre)
    if numba and kernels() is not None:
        return CompiledReach(n_atoms, init_facts, pre_of, adds, npre, no_pre)
    return None


def kernels():
    """The compiled (hadd, relaxed_plan, reach_without) functions, or None without numba."""
    global _kernels
    if _kernels is None:
        try:
            from gsr.plan import relax_kernels
        except ImportError:
            _kernels = False
        else:
            _kernels = (relax_kernels.hadd, relax_kernels.relaxed_plan, relax_kernels.reach_without)
    return _kernels or None


def _csr(rows: list[tuple[int, ...]] | list[list[int]]):
    import numpy as np

    ptr = np.zeros(len(rows) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(r) for r in rows])
    idx = np.fromiter((x for r in rows for x in r), dtype=np.int64, count=int(ptr[-1]))
    return ptr, idx


class CompiledRelaxation:
    """Flat arrays of one Relaxation and reusable work buffers for the compiled kernels."""

    def __init__(self, relax: UnaryRelaxation) -> None:
        import numpy as np

        self.hadd_kernel, self.plan_kernel, _ = kernels()
        n_facts, n_unary = relax.n_facts, len(relax.pre)
        self.n_atoms = len(relax.task.atoms)
        self.n_bytes = (self.n_atoms + 7) // 8 + 1
        self.true_fact, self.goal = relax.true_fact, relax.goal_fact
        self.stop = relax.goal_stop
        comp = sorted(relax.comp.items())
        self.comp_atom = np.array([a for a, _ in comp], dtype=np.int64)
        self.comp_fact = np.array([c for _, c in comp], dtype=np.int64)
        self.pre_of_ptr, self.pre_of_idx = _csr(relax.pre_of)
        self.add_ptr, self.add_idx = _csr(relax.add)
        self.pre_ptr, self.pre_idx = _csr(relax.pre)
        self.npre = np.array(relax.npre, dtype=np.int64)
        self.ucost = np.array(relax.cost, dtype=np.int64)
        self.owner = np.array(relax.owner, dtype=np.int64)
        self.cost = np.empty(n_facts, dtype=np.int64)
        self.sup = np.empty(n_facts, dtype=np.int64)
        self.acc = np.empty(n_unary, dtype=np.int64)
        self.unsat = np.empty(n_unary, dtype=np.int64)
        self.first = np.empty(n_facts + 1, dtype=np.int64)
        pushes = int(self.add_ptr[-1]) + n_facts + 1  # each push lowers a fact's cost via one edge
        self.hk = np.empty(pushes, dtype=np.int64)
        self.hc = np.empty(pushes, dtype=np.int64)
        self.hf = np.empty(pushes, dtype=np.int64)
        self.seen = np.zeros(n_facts, dtype=np.int64)
        self.mark = np.zeros(len(relax.task.ops), dtype=np.int64)
        self.stack = np.empty(n_facts + 1, dtype=np.int64)
        self.out = np.empty(len(relax.task.ops) + 1, dtype=np.int64)
        self.stamp = 0
        self.np = np

    def hadd(self, state: int) -> None:
        """Fill ``self.cost`` and ``self.sup`` for ``state`` (UNREACHED for unreached facts)."""
        np = self.np
        raw = np.frombuffer(state.to_bytes(self.n_bytes, "little"), dtype=np.uint8)
        self.hadd_kernel(
            raw,
            self.n_atoms,
            self.true_fact,
            self.comp_atom,
            self.comp_fact,
            self.pre_of_ptr,
            self.pre_of_idx,
            self.add_ptr,
            self.add_idx,
            self.npre,
            self.ucost,
            self.goal,
            self.stop,
            self.cost,
            self.sup,
            self.acc,
            self.unsat,
            self.first,
            self.hk,
            self.hc,
            self.hf,
        )

    def ff_plan(self, state: int) -> list[int] | None:
        """h_add, then the relaxed plan's operators; None when the goal is unreachable."""
        self.hadd(state)
        if self.cost[self.goal] >= UNREACHED:
            return None
        return self.relaxed_plan()

    def relaxed_plan(self) -> list[int]:
        """The operators of the relaxed plan from the last ``hadd`` (the goal must be reached)."""
        self.stamp += 1
        n = self.plan_kernel(
            self.goal,
            self.sup,
            self.pre_ptr,
            self.pre_idx,
            self.owner,
            self.seen,
            self.mark,
            self.stamp,
            self.stack,
            self.out,
        )
        return self.out[:n].tolist()


class CompiledReach:
    """Landmarks' "reachable without this fact" exploration over flat arrays (see
    gsr.plan.landmarks): the same reached facts as the Python exploration."""

    def __init__(self, n_atoms: int, init_facts: list[int], pre_of, adds, npre, no_pre) -> None:
        import numpy as np

        self.np = np
        self.kernel = kernels()[2]
        self.first = np.array(init_facts, dtype=np.int64)
        self.pre_of_ptr, self.pre_of_idx = _csr([pre_of.get(f, ()) for f in range(n_atoms)])
        self.add_ptr, self.add_idx = _csr(adds)
        self.npre = np.array(npre, dtype=np.int64)
        self.no_pre = np.array(no_pre, dtype=np.int64)
        self.unsat = np.empty(len(npre), dtype=np.int64)
        self.seen = np.empty(n_atoms, dtype=np.uint8)
        self.queue = np.empty(n_atoms, dtype=np.int64)

    def reached(self, facts: tuple[int, ...]) -> int:
        """The reached facts as a bitset when ``facts`` are never added."""
        np = self.np
        self.kernel(
            self.first,
            np.array(facts, dtype=np.int64),
            self.pre_of_ptr,
            self.pre_of_idx,
            self.add_ptr,
            self.add_idx,
            self.npre,
            self.no_pre,
            self.unsat,
            self.seen,
            self.queue,
        )
        return int.from_bytes(np.packbits(self.seen, bitorder="little").tobytes(), "little")
