"""Fixtures for the benchmark tests: the domain and the published GSR-Bench dev configs (skipped when absent)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.pddl.model import Domain


@pytest.fixture(scope="session")
def domain() -> Domain:
    """The tabletop domain."""
    from gsr.resources import load_builtin_domain

    return load_builtin_domain("tabletop")


@pytest.fixture(scope="session")
def gsr_bench_file(published_gsr_bench_file: Path) -> Path:
    """The 90 public GSR-Bench dev configs (skipped when absent: never shipped)."""
    return published_gsr_bench_file


@pytest.fixture(scope="session")
def gsr_bench_tasks(gsr_bench_file: Path) -> list:
    """All dev configs imported."""
    from gsr.benchmarks.suites.gsr_bench import load_gsr_bench

    return load_gsr_bench(gsr_bench_file)
