"""The shipped building, loaded once."""

from __future__ import annotations

import pytest

from gsr.building.model import Building
from gsr.building.shipped import load_shipped_building


@pytest.fixture(scope="session")
def shipped() -> Building:
    """data/buildings/three_floor.json."""
    return load_shipped_building()
