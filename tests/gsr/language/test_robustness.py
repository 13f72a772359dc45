"""Garbage never crashes: any word sequence grounds to a goal or raises GroundingError."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from gsr.language import GroundingError, ground
from gsr.language.lexicon import FUNCTION_WORDS
from tests.gsr.language.scene_fixture import scene

_SCENE = scene()
_WORDS = sorted(
    {
        *FUNCTION_WORDS,
        "red",
        "blue",
        "cube",
        "cubes",
        "box",
        "drawer",
        "milk",
        "book",
        "table",
        "blue_box",
        "xyzzy",
    }
)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.sampled_from(_WORDS), min_size=1, max_size=9))
def test_random_word_sequences(words: list[str]) -> None:
    text = " ".join(words)
    try:
        goal = ground(text, _SCENE)
    except GroundingError as exc:
        assert str(exc)
    else:
        assert goal.text == text
