"""The C kernels of ``relax_kernels.c``: built once with the system's C compiler, loaded with ctypes.

Why C besides numba: numba's kernels are fast, but switching to them costs ~1.2 s CPU and ~150 MB
per process (``import numba``, its LLVM set-up on the first call of a cached kernel), which is most
of GSR's time on mid-size IPC problems. A shared library built from ``relax_kernels.c`` loads in
milliseconds and needs neither numba nor numpy, so the compiled relaxation can be used from the
start of nearly every search.

The library is compiled on first use (``$CC``, ``cc``, or Zig's ``cc`` from the ``ziglang`` wheel when
the machine has no compiler: ``pip install 'gsr[compiler]'``; ``-O2 -shared -fPIC``; ~0.5 s once) into
the first writable of: this package's ``__pycache__``, ``$XDG_CACHE_HOME/gsr`` (``~/.cache/gsr``),
the temporary directory. Its name carries a hash of the source, the compiler command and the
platform, so an edited source is rebuilt and a stale library never loaded; it is written to a
temporary file and renamed (several processes may build at once). Without a compiler, or when the
build fails, ``library()`` is None and the planner uses numba or Python (``why_not`` says why).
``GSR_PLAN_CC=0`` forbids the C kernels; ``CC`` names the compiler.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from array import array
from itertools import accumulate, chain
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import ctypes

    from gsr.plan.relax_arrays import UnaryRelaxation
    from gsr.plan.task import Task

SOURCE = Path(__file__).with_name("relax_kernels.c")
FLAGS = ("-O2", "-shared", "-fPIC")
UNREACHED = 1 << 62  # the kernel's cost of an unreached fact
# Costs below this pop from FIFO buckets (a table grown on demand), costs above it from a heap.
MAX_BUCKETS = 1 << 20

_lib: ctypes.CDLL | bool | None = None  # False once building or loading failed
why_not = ""  # why the C kernels are unavailable (empty while they are, or before the first try)


def allowed() -> bool:
    """False when GSR_PLAN_CC=0 or GSR_PLAN_JIT=0 forbids the C kernels."""
    return os.environ.get("GSR_PLAN_CC", "") != "0" and os.environ.get("GSR_PLAN_JIT", "") != "0"


def c_compiler() -> list[str] | None:
    """``$CC``, else the system's ``cc``/``gcc``, else Zig's C compiler from the ``ziglang`` wheel.

    The last makes the C kernels a plain ``pip install`` away on a machine without a toolchain
    (``pip install 'gsr[compiler]'``); the first build then also fills Zig's own cache (~8 s once).
    """
    env = os.environ.get("CC", "").split()
    if env:
        return env
    system = shutil.which("cc") or shutil.which("gcc")
    if system:
        return [system]
    if importlib.util.find_spec("ziglang") is not None:
        return [sys.executable, "-m", "ziglang", "cc"]
    return None


def _cache_dirs() -> list[Path]:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return [Path(__file__).with_name("__pycache__"), Path(base) / "gsr", Path(tempfile.gettempdir()) / "gsr"]


def _build(cc: list[str], target: Path) -> str:
    """Compile into ``target`` atomically; returns an error message, or "" on success."""
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=target.stem + ".", suffix=".tmp.so", dir=target.parent)
        os.close(fd)
    except OSError as err:
        return f"cannot write to {target.parent}: {err}"
    try:
        run = subprocess.run(
            [*cc, *FLAGS, "-o", tmp, str(SOURCE)], capture_output=True, text=True, timeout=120, check=False
        )
        if run.returncode != 0:
            return f"{' '.join(cc)} failed: {(run.stderr or run.stdout).strip().splitlines()[-1:]}"
        os.replace(tmp, target)
        return ""
    except (OSError, subprocess.SubprocessError) as err:
        return f"{' '.join(cc)} failed: {err}"
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def library() -> ctypes.CDLL | None:
    """The loaded kernels (building them on first use), or None when they cannot be built or loaded."""
    global _lib, why_not
    if _lib is None:
        _lib = False
        if not allowed():
            why_not = "forbidden by GSR_PLAN_CC=0 or GSR_PLAN_JIT=0"
            return None
        cc = c_compiler()
        if cc is None:
            why_not = "no C compiler (set CC, install cc, or pip install 'gsr[compiler]' for Zig's)"
            return None
        key = hashlib.sha256(
            SOURCE.read_bytes() + " ".join((*cc, *FLAGS, platform.machine(), sys.platform)).encode()
        ).hexdigest()[:16]
        name = f"relax_kernels-{key}.so"
        errors = []
        for folder in _cache_dirs():
            target = folder / name
            if not target.is_file():
                error = _build(cc, target)
                if error:
                    errors.append(error)
                    continue
            try:
                _lib = _load(target)
                why_not = ""
                break
            except OSError as err:
                errors.append(f"cannot load {target}: {err}")
        else:
            why_not = "; ".join(dict.fromkeys(errors)) or "no writable cache directory"
    return _lib or None


def _load(path: Path) -> ctypes.CDLL:
    import ctypes

    lib = ctypes.CDLL(str(path))
    i64, ptr, buf = ctypes.c_int64, ctypes.c_void_p, ctypes.c_char_p
    lib.gsr_relax_new.restype = ptr
    lib.gsr_relax_new.argtypes = [i64] * 9 + [ptr] * 13
    lib.gsr_relax_set_lifo.restype = None
    lib.gsr_relax_set_lifo.argtypes = [ptr, i64]
    lib.gsr_relax_free.restype = None
    lib.gsr_relax_free.argtypes = [ptr]
    lib.gsr_hadd.restype = i64
    lib.gsr_hadd.argtypes = [ptr, buf, i64]
    lib.gsr_relaxed_plan.restype = i64
    lib.gsr_relaxed_plan.argtypes = [ptr, ptr]
    lib.gsr_ff.restype = i64
    lib.gsr_ff.argtypes = [ptr, buf, i64, ptr, ptr]
    lib.gsr_relax_set_ops.restype = None
    lib.gsr_relax_set_ops.argtypes = [ptr] * 5
    lib.gsr_reach_without.restype = None
    lib.gsr_reach_without.argtypes = [
        i64,
        ptr,
        i64,
        ptr,
        i64,
        ptr,
        ptr,
        ptr,
        ptr,
        ptr,
        ptr,
        i64,
        ptr,
        i64,
        ptr,
        ptr,
        ptr,
    ]
    lib.gsr_applicable.restype = i64
    lib.gsr_applicable.argtypes = [buf, i64, i64, ptr, i64, ptr, ptr, ptr, ptr, ptr, ptr, ptr]
    return lib


def _ints(values) -> array:
    return array("q", values)


def _csr(rows) -> tuple[array, array]:
    """Compressed rows: offsets (``len(rows) + 1``) and the concatenated values (built in C loops:
    a Python loop over the rows was ~1/4 of a tabletop task's set-up)."""
    rows = rows if isinstance(rows, list) else list(rows)
    # From lists: an array built from an iterator appends item by item (~25% slower).
    return array("q", [0, *accumulate(map(len, rows))]), array("q", list(chain.from_iterable(rows)))


def _addr(a: array) -> int:
    return a.buffer_info()[0]


class CRelaxation:
    """One Relaxation's arrays in C: h_add, the relaxed plan and h_FF's operators per call.

    Same interface as ``relax_jit.CompiledRelaxation``: ``hadd(state)`` fills ``cost`` and ``sup``
    (``array('q')``, UNREACHED for unreached facts), ``relaxed_plan()`` reads them, and
    ``ff_plan(state)`` does both in one call (None when the goal is unreachable).
    """

    def __init__(self, relax: UnaryRelaxation, lib: ctypes.CDLL) -> None:
        self.lib = lib
        n_facts, n_unary, n_ops = relax.n_facts, len(relax.pre), len(relax.task.ops)
        self.n_atoms = len(relax.task.atoms)
        self.n_bytes = (self.n_atoms + 7) // 8 + 1
        self.goal = relax.goal_fact
        comp = sorted(relax.comp.items())
        # The arrays the C context points into (kept alive with it; CSuccessors shares the operators').
        self.arrays = arrays = {
            "comp_atom": _ints([a for a, _ in comp]),
            "comp_fact": _ints([c for _, c in comp]),
            "npre": _ints(relax.npre),
            "ucost": _ints(relax.cost),
            "owner": _ints(relax.owner),
        }
        arrays["pre_of_ptr"], arrays["pre_of_idx"] = _csr(relax.pre_of)
        arrays["add_ptr"], arrays["add_idx"] = _csr(relax.add)
        arrays["pre_ptr"], arrays["pre_idx"] = _csr(relax.pre)
        arrays["opre_ptr"], arrays["opre_idx"] = _csr([o.pre for o in relax.task.ops])
        arrays["oneg_ptr"], arrays["oneg_idx"] = _csr([o.neg for o in relax.task.ops])
        self.cost = array("q", bytes(8 * n_facts))
        self.sup = array("q", bytes(8 * n_facts))
        self.out = array("q", bytes(8 * (n_ops + 1)))
        self._out_addr = _addr(self.out)
        self.n_pref = array("q", [0])
        self._n_pref_addr = _addr(self.n_pref)
        names = ("comp_atom", "comp_fact", "pre_of_ptr", "pre_of_idx", "add_ptr", "add_idx", "pre_ptr")
        names += ("pre_idx", "npre", "ucost", "owner")
        ctx = lib.gsr_relax_new(
            self.n_atoms,
            n_facts,
            n_unary,
            n_ops,
            relax.true_fact,
            relax.goal_fact,
            relax.goal_stop,
            len(comp),
            MAX_BUCKETS,
            *(_addr(arrays[k]) for k in names),
            _addr(self.cost),
            _addr(self.sup),
        )
        if not ctx:
            raise MemoryError("cannot allocate the C relaxation's work buffers")
        self.ctx = ctx
        lib.gsr_relax_set_ops(
            ctx, *(_addr(arrays[k]) for k in ("opre_ptr", "opre_idx", "oneg_ptr", "oneg_idx"))
        )
        if getattr(relax, "lifo", False):
            lib.gsr_relax_set_lifo(ctx, 1)
        self._hadd, self._ff = lib.gsr_hadd, lib.gsr_ff
        self.unit = relax.unit
        self.op_cost = [o.cost for o in relax.task.ops]

    def set_lifo(self, lifo: bool) -> None:
        """h_add's buckets above cost 0 last in first out (``Relaxation.lifo``) or FIFO."""
        self.lib.gsr_relax_set_lifo(self.ctx, 1 if lifo else 0)

    def __del__(self) -> None:
        ctx, self.ctx = getattr(self, "ctx", None), None
        if ctx:
            self.lib.gsr_relax_free(ctx)

    def hadd(self, state: int) -> None:
        """Fill ``self.cost`` and ``self.sup`` for ``state``."""
        if self._hadd(self.ctx, state.to_bytes(self.n_bytes, "little"), self.n_bytes) < 0:
            raise MemoryError("h_add's bucket table cannot grow")

    def relaxed_plan(self) -> list[int]:
        """The operators of the relaxed plan from the last ``hadd`` (the goal must be reached)."""
        n = self.lib.gsr_relaxed_plan(self.ctx, self._out_addr)
        return self.out[:n].tolist()

    def ff_plan(self, state: int) -> list[int] | None:
        """h_add and the relaxed plan's operators in one call; None when the goal is unreachable."""
        n = self._ff(
            self.ctx, state.to_bytes(self.n_bytes, "little"), self.n_bytes, self._out_addr, self._n_pref_addr
        )
        if n == -2:
            raise MemoryError("h_add's bucket table cannot grow")
        return None if n < 0 else self.out[:n].tolist()

    def ff(self, state: int) -> tuple[float, list[int]] | None:
        """h_FF (the relaxed plan's size, or its cost without unit costs) and the preferred operators
        (the plan's operators applicable in ``state``) in one call; None when the goal is unreachable."""
        n = self._ff(
            self.ctx, state.to_bytes(self.n_bytes, "little"), self.n_bytes, self._out_addr, self._n_pref_addr
        )
        if n < 0:
            if n == -2:
                raise MemoryError("h_add's bucket table cannot grow")
            return None
        out = self.out
        if self.unit:
            return n, out[: self.n_pref[0]].tolist()
        cost = self.op_cost
        return sum(cost[o] for o in out[:n]), out[: self.n_pref[0]].tolist()


class CReach:
    """Landmarks' "reachable without this fact" exploration in C (see gsr.plan.landmarks)."""

    def __init__(self, lib: ctypes.CDLL, n_atoms: int, init_facts, pre_of, adds, npre, no_pre) -> None:
        self.fn = lib.gsr_reach_without
        self.n_atoms = n_atoms
        self.first = _ints(init_facts)
        self.pre_of_ptr, self.pre_of_idx = _csr([pre_of.get(f, ()) for f in range(n_atoms)])
        self.add_ptr, self.add_idx = _csr(adds)
        self.npre = _ints(npre)
        self.no_pre = _ints(no_pre)
        self.unsat = array("q", bytes(8 * max(len(npre), 1)))
        self.seen = bytearray(n_atoms + 1)
        self.queue = array("q", bytes(8 * (n_atoms + 1)))
        self.reached_bytes = bytearray((n_atoms + 7) // 8 + 1)
        import ctypes

        self._seen = (ctypes.c_char * len(self.seen)).from_buffer(self.seen)
        self._reached = (ctypes.c_char * len(self.reached_bytes)).from_buffer(self.reached_bytes)
        self._args = (
            n_atoms,
            _addr(self.first),
            len(self.first),
        )
        self._rest = (
            _addr(self.pre_of_ptr),
            _addr(self.pre_of_idx),
            _addr(self.add_ptr),
            _addr(self.add_idx),
            _addr(self.npre),
            _addr(self.no_pre),
            len(self.no_pre),
            _addr(self.unsat),
            len(self.npre),
            ctypes.addressof(self._seen),
            _addr(self.queue),
            ctypes.addressof(self._reached),
        )

    def reached(self, facts: tuple[int, ...]) -> int:
        """The reached facts as a bitset when ``facts`` are never added."""
        blocked = _ints(facts)
        self.fn(*self._args, _addr(blocked), len(blocked), *self._rest)
        return int.from_bytes(self.reached_bytes, "little")


class CSuccessors:
    """``Task.applicable`` in C: the same operator index (each operator under one precondition
    atom), each candidate tested on its precondition atoms; ascending ids, as the Python path."""

    def __init__(self, task: Task, lib: ctypes.CDLL, relaxation: CRelaxation | None = None) -> None:
        """``relaxation``: a CRelaxation of the same task, whose operator precondition arrays are
        shared instead of built again."""
        self.fn = lib.gsr_applicable
        self.n_atoms = len(task.atoms)
        self.n_bytes = (self.n_atoms + 7) // 8 + 1
        self.always = _ints(task.always)
        self.by_ptr, self.by_idx = _csr(task.by_fact)
        if relaxation is not None:
            keep = relaxation.arrays
            self.pre_ptr, self.pre_idx = keep["opre_ptr"], keep["opre_idx"]
            self.neg_ptr, self.neg_idx = keep["oneg_ptr"], keep["oneg_idx"]
        else:
            self.pre_ptr, self.pre_idx = _csr([o.pre for o in task.ops])
            self.neg_ptr, self.neg_idx = _csr([o.neg for o in task.ops])
        self.out = array("q", bytes(8 * (len(task.ops) + 1)))
        self._mid = (
            self.n_atoms,
            _addr(self.always),
            len(self.always),
            _addr(self.by_ptr),
            _addr(self.by_idx),
            _addr(self.pre_ptr),
            _addr(self.pre_idx),
            _addr(self.neg_ptr),
            _addr(self.neg_idx),
            _addr(self.out),
        )

    def applicable(self, state: int) -> list[int]:
        """Ids of the operators applicable in ``state``, ascending."""
        n = self.fn(state.to_bytes(self.n_bytes, "little"), self.n_bytes, *self._mid)
        return self.out[:n].tolist()
