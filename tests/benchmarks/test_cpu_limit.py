"""The benchmarks' CPU limit (``--clock cpu``) raises once, however long the unwinding takes."""

from __future__ import annotations

import multiprocessing
import time

import pytest
from gsr.benchmarks import bench_ipc_language, bench_planner


def _spin(seconds: float) -> None:
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def _child(module_name: str, queue) -> None:
    module = bench_planner if module_name == "planner" else bench_ipc_language
    module.limit_cpu(1)
    try:
        _spin(30)
        queue.put("no limit")
        return
    except module.CpuLimit:
        pass
    try:
        _spin(2.2)  # longer than the kernel's one-second repeat of SIGXCPU past the soft limit
    except module.CpuLimit:
        queue.put("raised twice")
        return
    queue.put("once")


@pytest.mark.parametrize("module_name", ["planner", "ipc"])
def test_cpu_limit_raises_once(module_name: str) -> None:
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    proc = ctx.Process(target=_child, args=(module_name, queue))
    proc.start()
    proc.join(60)
    assert proc.exitcode == 0
    assert queue.get(timeout=5) == "once"
