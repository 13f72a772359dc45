"""Service test helpers: an app over a private state directory whose worker processes are stopped after."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from gsr.service import ServiceSettings, create_app

SCENE = {
    "nodes": ["table", "blue_box", "red_cube1", "red_cube2"],
    "edges": ["blue_box(on)table", "red_cube1(on)table", "red_cube2(on)blue_box"],
}


@pytest.fixture
def make_client(tmp_path: Path) -> Iterator[Callable[..., TestClient]]:
    """``make_client(**settings)``: a TestClient over a fresh app; its worker processes end with the test."""
    apps = []

    def make(**overrides) -> TestClient:
        overrides.setdefault("state_dir", str(tmp_path / "state"))
        app = create_app(ServiceSettings(**overrides))
        apps.append(app)
        return TestClient(app)

    yield make
    for app in apps:
        app.state.pool.close()
