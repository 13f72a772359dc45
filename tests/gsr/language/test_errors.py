"""Not understood or ambiguous: GroundingError names the unknown words or the candidate objects."""

from __future__ import annotations

import pytest

from gsr.errors import GSRError
from gsr.language import GroundingError, ground
from tests.gsr.language.scene_fixture import scene


def _error(text: str) -> GroundingError:
    with pytest.raises(GroundingError) as info:
        ground(text, scene())
    return info.value


def test_is_a_gsr_error() -> None:
    assert issubclass(GroundingError, GSRError)


def test_unknown_words_are_named() -> None:
    err = _error("put the red cube in the blue bxo and wiggle it")
    assert err.unknown_words == ("bxo", "wiggle")
    assert "'bxo'" in str(err) and "'wiggle'" in str(err)


def test_ambiguous_reference_lists_candidates() -> None:
    err = _error("put the red cube in the yellow box")
    assert err.candidates == ("red_cube1", "red_cube2")
    assert "ambiguous" in str(err) and "red_cube1" in str(err)


def test_ambiguous_destination_lists_candidates() -> None:
    err = _error("put all cubes in the box")
    assert set(err.candidates) == {"red_box", "blue_box", "yellow_box"}


def test_no_match_names_the_phrase_and_near_misses() -> None:
    err = _error("put the green cube in the blue box")
    assert err.phrase == "the green cube"
    assert "yellow_cube1" in err.candidates


def test_unparseable_sentence() -> None:
    err = _error("the red cube blue box")
    assert "cannot understand" in str(err)


def test_wrong_affordance() -> None:
    err = _error("open the milk")
    assert err.candidates == ("milk",) and "cannot be opened" in str(err)


def test_pronoun_without_antecedent() -> None:
    assert "'it'" in str(_error("put it in the red box"))


def test_spatial_goal_without_a_region() -> None:
    assert "region" in str(_error("put the milk to the left of the popcorn"))


def test_both_needs_two() -> None:
    err = _error("put both cubes in the red box")
    assert len(err.candidates) == 4


def test_empty_instruction() -> None:
    with pytest.raises(GroundingError):
        ground("   ", scene())
