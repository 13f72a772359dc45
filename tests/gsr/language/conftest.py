"""Helpers for the language tests: goal equivalence by ground DNF, and the reference data sets."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.language.equivalence import ground_dnf
from gsr.pddl.model import Domain
from gsr.resources import load_builtin_domain

__all__ = ["ground_dnf"]


@pytest.fixture(scope="session")
def domain() -> Domain:
    """The tabletop domain."""
    return load_builtin_domain("tabletop")


@pytest.fixture(scope="session")
def libero_files(libero_dir: Path) -> list[Path]:
    """The 40 shipped LIBERO task files."""
    files = sorted(libero_dir.glob("*/*.bddl"))
    assert len(files) == 40
    return files


@pytest.fixture(scope="session")
def gsr_bench_configs(published_gsr_bench_file: Path) -> list[dict]:
    """The 90 published GSR-Bench dev configs (skipped when absent: never shipped)."""
    import yaml

    data = yaml.safe_load(published_gsr_bench_file.read_text(encoding="utf-8"))
    configs = data["configs"]
    assert len(configs) == 90
    return configs
