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
def libero_files(shared_data: Path) -> list[Path]:
    """The 40 LIBERO task files."""
    files = sorted((shared_data / "libero").glob("*/*.bddl"))
    assert len(files) == 40
    return files


@pytest.fixture(scope="session")
def gsr_bench_configs(shared_data: Path) -> list[dict]:
    """The 90 GSR-Bench dev configs."""
    import yaml

    data = yaml.safe_load((shared_data / "gsr_bench" / "saved_configs_dev.yaml").read_text(encoding="utf-8"))
    configs = data["configs"]
    assert len(configs) == 90
    return configs
