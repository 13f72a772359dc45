"""Shared fixtures: the shipped building, its map and instruction parser."""

from __future__ import annotations

import pytest
from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.shipped import load_shipped_building
from gsr.benchmarks.delivery.parser import InstructionParser
from gsr.benchmarks.delivery.run import parser_for


@pytest.fixture(scope="session")
def shipped() -> Building:
    """data/buildings/three_floor.json."""
    return load_shipped_building()


@pytest.fixture(scope="session")
def bmap(shipped: Building) -> BuildingMap:
    """The shipped building's navigation map."""
    return BuildingMap(shipped)


@pytest.fixture(scope="session")
def parser(shipped: Building) -> InstructionParser:
    """The shipped building's instruction parser."""
    return parser_for(shipped)
