"""The step language: text and JSON syntax, round trips, errors with line and column."""

from __future__ import annotations

import contextlib
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gsr.errors import ParseError
from gsr.pddl.model import Atom
from gsr.reason import format_steps, parse_first_step, parse_steps
from gsr.step import Step

LINE = (
    "(place_in bowl_1 cabinet_1/bottom_drawer) +(in bowl_1 cabinet_1/bottom_drawer) "
    "-(holding bowl_1) +(hand_empty)"
)


def test_text_line_with_effects():
    (step,) = parse_steps(LINE)
    assert step.action == "place_in"
    assert step.args == ("bowl_1", "cabinet_1/bottom_drawer")
    assert step.add == (Atom("in", ("bowl_1", "cabinet_1/bottom_drawer")), Atom("hand_empty", ()))
    assert step.delete == (Atom("holding", ("bowl_1",)),)


def test_line_without_effects_makes_no_claim():
    (step,) = parse_steps("(open short_cabinet/drawer_low)")
    assert step.add is None and step.delete is None and not step.claims_effects


def test_markers_comments_fences_and_case():
    text = "```\n1. (OPEN D)\n- (pick A-1 T) +(holding a-1)  ; why\n* (close d)\nstep 4: (open d)\n```\n"
    steps = parse_steps(text)
    assert [s.action for s in steps] == ["open", "pick", "close", "open"]
    assert steps[1].args == ("a-1", "t") and steps[1].add == (Atom("holding", ("a-1",)),)
    assert steps[1].delete == ()  # an effect list claims the full change


def test_json_lines_and_list():
    obj = {"action": "pick", "args": ["a", "b"], "add": [["holding", "a"]], "delete": ["(hand_empty)"]}
    for text in (json.dumps(obj), json.dumps([obj, {"action": "open", "args": ["d"]}])):
        steps = parse_steps(text)
        assert steps[0] == Step("pick", ("a", "b"), (Atom("holding", ("a",)),), (Atom("hand_empty", ()),))
    assert parse_steps(json.dumps([obj, {"action": "open", "args": ["d"]}]))[1] == Step("open", ("d",))


@pytest.mark.parametrize(
    ("text", "line", "column", "fragment"),
    [
        ("(pick a", 1, 8, "end of line"),
        ("(open d)\npick a b", 2, 1, "unexpected 'pick'"),
        ("(pick a b) +holding", 1, 13, "unexpected 'holding'"),
        ("(pick a b) (holding a)", 1, 12, "unexpected '('"),
        ('(pick a b)\n\n{"action": 3}', 3, 1, "field 'action'"),
        ('{"action": "pick", "args": "a"}', 1, 1, "field 'args'"),
        ('{"action": "pick", "oops": 1}', 1, 1, "unknown field"),
        ('{"action": "pick", "add": [7]}', 1, 1, "expected an atom"),
        ("```\n[{]", 2, 3, "invalid JSON"),
    ],
)
def test_errors_have_line_and_column(text, line, column, fragment):
    with pytest.raises(ParseError) as err:
        parse_steps(text, source="reply")
    assert (err.value.line, err.value.column) == (line, column)
    assert fragment in str(err.value) and str(err.value).startswith(f"reply:{line}:{column}")


def test_first_step_ignores_later_lines_and_rejects_empty():
    assert parse_first_step("\n(open d)\nthis is not a step").action == "open"
    with pytest.raises(ParseError, match="empty"):
        parse_first_step("```\n```")


_FIRST = "abcdefghijklmnopqrstuvwxyz0123456789_"
NAME = st.builds(
    lambda a, b: a + b, st.sampled_from(_FIRST), st.text(alphabet=_FIRST + "-/.", max_size=8)
)  # plain strategies: a regex strategy is too slow on a loaded machine
ATOM = st.builds(Atom, NAME, st.lists(NAME, max_size=3).map(tuple))
STEP = st.builds(
    Step,
    NAME,
    st.lists(NAME, max_size=3).map(tuple),
    st.lists(ATOM, min_size=1, max_size=3).map(tuple),
    st.lists(ATOM, max_size=3).map(tuple),
)


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(st.lists(STEP, max_size=4))
def test_round_trip_text_and_json(steps):
    assert parse_steps(format_steps(steps)) == steps
    assert parse_steps(format_steps(steps, json_format=True)) == steps


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(st.text(max_size=60))
def test_garbage_never_crashes(text):
    with contextlib.suppress(ParseError):
        parse_steps(text)
