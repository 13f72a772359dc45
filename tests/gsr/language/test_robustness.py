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


def _libero_scene():
    from gsr.libero import libero_graph
    from gsr.pddl.bddl import load_bddl
    from tests.data_paths import LIBERO

    return libero_graph(load_bddl(LIBERO / "libero_goal" / "put_the_bowl_on_the_plate.bddl"))


_LIBERO = _libero_scene()
_EVERYDAY = sorted(
    {
        *_WORDS,
        "2",
        "0",
        "99",
        "two",
        "a couple of",
        "everything",
        "except",
        "whose",
        "matches",
        "own",
        "no",
        "share",
        "each",
        "other",
        "ones",
        "one",
        "give",
        "fill",
        "with",
        "keep",
        "finish",
        "tidy up",
        "cups",
        "drinks",
        "bowl",
        "plate",
        "stove",
        "cabinet",
        "the",
        "it",
        "them",
        "'s",
        "don't",
        "?",
        ",",
        ".",
    }
)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.sampled_from(_EVERYDAY) | st.text(max_size=6), min_size=0, max_size=12),
    st.booleans(),
)
def test_any_input_is_a_goal_or_a_clean_error(words: list[str], libero: bool) -> None:
    """Everyday words, numbers, punctuation and arbitrary unicode: a goal or a GroundingError, nothing else."""
    text = " ".join(words)
    try:
        goal = ground(text, _LIBERO if libero else _SCENE)
    except GroundingError as exc:
        assert exc.message
    else:
        assert goal.text == text


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=80))
def test_arbitrary_text_never_crashes(text: str) -> None:
    try:
        ground(text, _SCENE)
    except GroundingError as exc:
        assert exc.message
