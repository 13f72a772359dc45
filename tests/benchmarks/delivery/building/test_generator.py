"""Generated buildings: deterministic per seed, sound for many seeds and sizes."""

from __future__ import annotations

import pytest
from gsr.benchmarks.delivery.building.checks import building_problems
from gsr.benchmarks.delivery.building.generator import generate_building
from gsr.benchmarks.delivery.building.model import Building


def test_same_seed_same_building() -> None:
    assert generate_building(3).to_json() == generate_building(3).to_json()
    assert generate_building(3).to_json() != generate_building(4).to_json()


@pytest.mark.parametrize("seed", range(8))
def test_seeds_give_sound_buildings(seed: int) -> None:
    b = generate_building(seed)
    assert building_problems(b) == []
    assert sum(r.kind != "corridor" for r in b.rooms) == 24


@pytest.mark.parametrize(("floors", "people"), [(1, 6), (2, 10), (4, 15)])
def test_other_sizes(floors: int, people: int) -> None:
    b = generate_building(11, floors=floors, people=people)
    assert len(b.floors) == floors and len(b.people) == people
    assert building_problems(b) == []


def test_bad_parameters() -> None:
    with pytest.raises(ValueError, match="floors"):
        generate_building(0, floors=0)
    with pytest.raises(ValueError, match="at most"):
        generate_building(0, people=50)


def test_json_round_trip() -> None:
    b = generate_building(5)
    assert Building.from_json(b.to_json()) == b
