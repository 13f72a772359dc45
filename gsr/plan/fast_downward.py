"""Optional delegation to Fast Downward (the driver shipped by ``up-fast-downward``, or ``fast-downward``)."""

from __future__ import annotations

import importlib.util
import os
import shutil
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


def run_fast_downward(
    domain_file: Path,
    problem_file: Path,
    timeout: float,
    *,
    alias: str | None = "lama-first",
    search: str | None = None,
) -> tuple[str, Plan | None, str]:
    """Run FD on two files; returns (status, plan, message) with status solved/unsolvable/timeout/error."""
    cmd = find_fast_downward()
    if cmd is None:
        raise GSRError(
            "Fast Downward is not available: pip install up-fast-downward, or put fast-downward on PATH"
        )
    with tempfile.TemporaryDirectory(prefix="gsr-fd-") as tmp:
        plan_file = Path(tmp) / "sas_plan"
        args = [*cmd, "--plan-file", str(plan_file)]
        if search is not None:
            args += [str(Path(domain_file).resolve()), str(Path(problem_file).resolve()), "--search", search]
        else:
            args += [
                "--alias",
                alias or "lama-first",
                str(Path(domain_file).resolve()),
                str(Path(problem_file).resolve()),
            ]
        env = dict(os.environ, PYTHONHASHSEED="0")
        try:
            proc = subprocess.run(args, cwd=tmp, capture_output=True, text=True, timeout=timeout, env=env)
        except subprocess.TimeoutExpired:
            return "timeout", None, f"Fast Downward exceeded {timeout:.1f} s"
        if plan_file.is_file():
            return "solved", parse_sas_plan(plan_file.read_text()), "fast downward"
        # Exit codes 11/12: proven unsolvable (https://www.fast-downward.org/ExitCodes); 23/21: limits.
        if proc.returncode in (11, 12):
            return "unsolvable", None, "Fast Downward proved the task unsolvable"
        if proc.returncode in (21, 23, 24):
            return "timeout", None, f"Fast Downward hit a limit (exit {proc.returncode})"
        tail = (proc.stdout + proc.stderr).strip().splitlines()[-3:]
        return "error", None, f"Fast Downward failed (exit {proc.returncode}): {' | '.join(tail)}"
