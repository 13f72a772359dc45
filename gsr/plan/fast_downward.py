"""Optional delegation to Fast Downward (the driver shipped by ``up-fast-downward``, or ``fast-downward``)."""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from gsr.errors import GSRError
from gsr.step import Plan, Step


def find_fast_downward() -> list[str] | None:
    """The command prefix that runs Fast Downward's driver, or None when it is not installed."""
    spec = importlib.util.find_spec("up_fast_downward")
    if spec is not None and spec.origin:
        driver = Path(spec.origin).parent / "downward" / "fast-downward.py"
        if driver.is_file():
            return [sys.executable, str(driver)]
    exe = shutil.which("fast-downward") or shutil.which("fast-downward.py")
    return [exe] if exe else None


def parse_sas_plan(text: str) -> Plan:
    """Parse Fast Downward's ``sas_plan`` (one ``(action args)`` per line, ``;`` comments)."""
    steps = []
    for line in text.splitlines():
        line = line.split(";", 1)[0].strip()
        if not line:
            continue
        tokens = line.strip("()").lower().split()
        steps.append(Step(tokens[0], tuple(tokens[1:])))
    return Plan(tuple(steps))


_TRANSLATOR_DONE = re.compile(r"^Done! \[([0-9.]+)s CPU, ([0-9.]+)s wall-clock\]", re.MULTILINE)
_TRANSLATOR_COUNT = re.compile(r"^Translator (operators|axioms): (\d+)", re.MULTILINE)


def translator_stats(log: str) -> dict:
    """From FD's log: ``translated`` (the translator finished), ``translate_cpu``/``translate_wall``
    (its own seconds) and ``operators``/``axioms`` (ground counts after its simplification)."""
    out: dict = {"translated": "translate exit code: 0" in log}
    done = _TRANSLATOR_DONE.search(log)
    if done:
        out["translate_cpu"], out["translate_wall"] = float(done.group(1)), float(done.group(2))
    for name, value in _TRANSLATOR_COUNT.findall(log):
        out[name] = int(value)
    return out


def run_fast_downward(
    domain_file: Path,
    problem_file: Path,
    timeout: float,
    *,
    alias: str | None = "lama-first",
    search: str | None = None,
    memory_limit: str | None = None,
    details: dict | None = None,
    cpu_limit: float | None = None,
) -> tuple[str, Plan | None, str]:
    """Run FD on two files; returns (status, plan, message) with status solved/unsolvable/timeout/error.

    ``details``, when given, receives what FD's log tells about its translator (translator_stats):
    whether it finished, its CPU and wall seconds, operator and axiom counts (also after a timeout).

    FD runs in its own session so that a timeout kills the translator and search processes too (the
    driver alone would leave an orphaned search running); ``memory_limit`` (e.g. "4G") is passed to
    the driver's --overall-memory-limit; ``cpu_limit`` (seconds) to its --overall-time-limit, which
    FD enforces on CPU time (``timeout`` stays the wall-clock limit of the whole run).
    """
    cmd = find_fast_downward()
    if cmd is None:
        raise GSRError(
            "Fast Downward is not available: pip install up-fast-downward, or put fast-downward on PATH"
        )
    with tempfile.TemporaryDirectory(prefix="gsr-fd-") as tmp:
        plan_file = Path(tmp) / "sas_plan"
        args = [*cmd, "--plan-file", str(plan_file)]
        if memory_limit is not None:
            args += ["--overall-memory-limit", memory_limit]
        if cpu_limit is not None:
            args += ["--overall-time-limit", f"{max(1, round(cpu_limit))}s"]
        if search is not None:
            args += [str(Path(domain_file).resolve()), str(Path(problem_file).resolve()), "--search", search]
        else:
            args += [
                "--alias",
                alias or "lama-first",
                str(Path(domain_file).resolve()),
                str(Path(problem_file).resolve()),
            ]
        # Unbuffered: the log of a run killed at the limit still says how far the translator got.
        env = dict(os.environ, PYTHONHASHSEED="0", PYTHONUNBUFFERED="1")
        proc = subprocess.Popen(
            args,
            cwd=tmp,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            start_new_session=True,
        )
        try:
            stdout, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            stdout, _ = proc.communicate()
            if details is not None:
                details.update(translator_stats(stdout or ""))
            return "timeout", None, f"Fast Downward exceeded {timeout:.1f} s"
        finally:
            if proc.poll() is None:  # interrupted (e.g. Ctrl-C): never leave FD running
                os.killpg(proc.pid, signal.SIGKILL)
        if details is not None:
            details.update(translator_stats(stdout))
        if plan_file.is_file():
            return "solved", parse_sas_plan(plan_file.read_text()), "fast downward"
        # Exit codes (https://www.fast-downward.org/ExitCodes): 11/12 proven unsolvable; 21/23 out of
        # time; 20/22/24 out of memory.
        if proc.returncode in (11, 12):
            return "unsolvable", None, "Fast Downward proved the task unsolvable"
        if proc.returncode in (21, 23):
            return "timeout", None, f"Fast Downward ran out of time (exit {proc.returncode})"
        if proc.returncode in (20, 22, 24):
            return "error", None, f"Fast Downward ran out of memory (exit {proc.returncode})"
        tail = (stdout + stderr).strip().splitlines()[-3:]
        return "error", None, f"Fast Downward failed (exit {proc.returncode}): {' | '.join(tail)}"
