"""Shared fixtures: where tests find data (see tests/data_paths.py).

Shipped data (``data/``, ``tests/fixtures/``) is always there; ``shared_data`` is the third-party
reference folder (``$GSR_SHARED_DATA`` or ``../shared/data``) and skips the test when it is absent.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.data_paths import BEHAVIOR, GSR_BENCH_FILE, LIBERO, NO_SHARED, PDDL, REPO, SHARED_DATA

__all__ = ["REPO", "SHARED_DATA"]


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The reference folder (LIBERO, IPC PDDL, BEHAVIOR, GSR-Bench, PRS); skips the test when absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(NO_SHARED)
    return SHARED_DATA


@pytest.fixture(scope="session")
def libero_dir() -> Path:
    """The 40 shipped LIBERO task files: ``data/libero/<suite>/<task>.bddl``."""
    return LIBERO


@pytest.fixture(scope="session")
def behavior_dir() -> Path:
    """The shipped BEHAVIOR-100 activities and ``domain_igibson.bddl``: ``data/behavior``."""
    return BEHAVIOR


@pytest.fixture(scope="session")
def pddl_dir() -> Path:
    """IPC sets (``<set>/domain.pddl`` + problems): ``tests/fixtures/pddl``."""
    return PDDL


@pytest.fixture(scope="session")
def published_gsr_bench_file() -> Path:
    """The published GSR-Bench dev configs (never shipped); skips the test when absent."""
    if not GSR_BENCH_FILE.is_file():
        pytest.skip(f"published GSR-Bench configs absent at {GSR_BENCH_FILE}: set GSR_SHARED_DATA")
    return GSR_BENCH_FILE


@pytest.fixture(scope="session")
def generated_gsr_bench_configs() -> list[dict]:
    """36 GSR-Bench-format configs from the project's generator (4 per cell), for format mechanics."""
    from tests.data_paths import generated_gsr_bench_configs

    return generated_gsr_bench_configs()


@pytest.fixture(scope="session", params=["generated", "published"])
def gsr_bench_style_configs(request: pytest.FixtureRequest) -> list[dict]:
    """GSR-Bench-format configs for format mechanics, twice: the project's generated ones (always) and the
    published dev configs (skipped when absent)."""
    if request.param == "generated":
        return request.getfixturevalue("generated_gsr_bench_configs")
    import yaml

    path = request.getfixturevalue("published_gsr_bench_file")
    return yaml.safe_load(path.read_text(encoding="utf-8"))["configs"]
