"""The one step grammar: reasoner step lines (effects on) and IPC plan lines (effects off)."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gsr.errors import ParseError
from gsr.pddl.model import Atom
from gsr.plan_format import parse_plan
from gsr.reason.step_format import parse_steps
from gsr.step import Step
from gsr.step_grammar import parse_step_text


def test_one_grammar_two_line_kinds() -> None:
    assert parse_step_text("3. (Pick A T) +(holding a) -(hand_empty)") == Step(
        "pick", ("a", "t"), (Atom("holding", ("a",)),), (Atom("hand_empty", ()),)
    )
    assert parse_step_text("1.5 : (Stack B ?a) [1]", effects=False) == Step("stack", ("b", "?a"))
    with pytest.raises(ParseError, match=r"unexpected '\+'") as err:  # a plan line claims no effects
        parse_step_text("(pick a t) +(holding a)", effects=False)
    assert err.value.column == 12
    with pytest.raises(ParseError, match=r"1:3: unexpected '5'"):  # "1." is a list marker, not a timestamp
        parse_step_text("1.5: (pick a t)")
    # both readers go through it
    assert parse_steps("- (open d)")[0] == parse_plan("0: (open d)").steps[0] == Step("open", ("d",))


def test_a_plan_line_that_ends_early_says_what_is_missing() -> None:
    with pytest.raises(ParseError) as err:
        parse_plan("(a)\n3: ", source="p.plan")
    assert str(err.value) == "p.plan:2:4: unexpected end of line (expected '(')"
    with pytest.raises(ParseError, match=r"missing '\)'"):
        parse_plan("(a b", source="p.plan")


CHARS = "aZ09_-./@#?+*:()[] \t"


LINES = st.one_of(
    st.text(alphabet=CHARS, max_size=20),
    st.builds(
        lambda pre, names, post: f"{pre}({' '.join(names)}){post}",
        st.sampled_from(["", " ", "3:", "1.5 :", "\t7."]),
        st.lists(st.text(alphabet="aZ09_-./@#?", min_size=1, max_size=4), min_size=1, max_size=3),
        st.sampled_from(["", " ", "[1]", " [ 2.5 ] ", " +(x)"]),
    ),
)


def _read(line: str, effects: bool, fast: bool = True) -> object:
    try:
        return parse_step_text(line, effects=effects, fast=fast)
    except ParseError as exc:
        return str(exc)


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None, max_examples=300)
@given(line=LINES, effects=st.booleans())
def test_the_fast_path_reads_lines_as_the_grammar_does(line: str, effects: bool) -> None:
    assert _read(line, effects) == _read(line, effects, fast=False)  # the same with every line through lark
