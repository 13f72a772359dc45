"""Goal serialisation for long goals (goal_window), the marker that sets it, and the long validation tasks."""

from __future__ import annotations

import json

import pytest

from gsr.pddl.model import And
from gsr.pddl.parser import parse_formula
from gsr.reason.compact_decode import window_goal
from gsr.resources import load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def graph() -> SceneGraph:
    return SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="red_box", category="box", attributes={"color": "red"}),
            Node(id="blue_box", category="box", attributes={"color": "blue"}),
            Node(id="cube1", category="cube"),
            Node(id="cube2", category="cube"),
        ),
        edges=(
            Edge(source="red_box", relation="on", target="table"),
            Edge(source="blue_box", relation="on", target="table"),
            Edge(source="cube1", relation="on", target="table"),
            Edge(source="cube2", relation="on", target="red_box"),
        ),
    )


GOAL = "(and (on cube1 blue_box) (on red_box table) (on cube2 table) (not (on cube1 table)))"


def test_window_keeps_the_holding_literals_and_the_first_open_ones(domain, graph) -> None:
    goal = parse_formula(GOAL)
    one = window_goal(goal, graph, domain, 1)
    assert isinstance(one, And)
    assert [str(p) for p in one.parts] == [
        str(p) for p in parse_formula("(and (on cube1 blue_box) (on red_box table))").parts
    ]
    two = window_goal(goal, graph, domain, 2)
    assert [str(p) for p in two.parts] == [
        str(p) for p in parse_formula("(and (on cube1 blue_box) (on red_box table) (on cube2 table))").parts
    ]
    # no more open literals than the window, or a goal that is not a conjunction of literals: unchanged
    assert window_goal(goal, graph, domain, 3) is goal
    either = parse_formula("(or (on cube1 blue_box) (on cube2 table) (on cube1 red_box))")
    assert window_goal(either, graph, domain, 1) is either


def test_the_answerer_shows_the_model_the_windowed_goal(domain, graph, monkeypatch) -> None:
    pytest.importorskip("transformers")
    import gsr.reason.compact_decode as decode
    from gsr.reason.backend import Query
    from gsr.reason.compact import build_tokenizer
    from gsr.reason.prompt import Prompt
    from gsr.train.compact import CompactSpec, new_model

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=128), 0)
    seen = []
    real = decode.query_tokens

    def spy(g, d, goal, history, version=1):
        seen.append(goal)
        return real(g, d, goal, history, version)

    monkeypatch.setattr(decode, "query_tokens", spy)
    goal = parse_formula(GOAL)
    lines = ("pick cube1 table", "pick cube2 red_box")
    for window in (None, 1):
        answerer = decode.CompactAnswerer(model, tok, goal_window=window)
        reply = answerer.answer(Query("step", Prompt("", ""), graph, domain, "", goal, (), lines))
        assert reply in lines
    assert seen[0] is goal and len(seen[1].parts) == 2


def test_the_marker_sets_the_backend_window_and_a_bad_one_is_refused(domain, tmp_path) -> None:
    pytest.importorskip("transformers")
    from gsr.reason.backend import BackendError
    from gsr.reason.compact import MARKER, build_tokenizer
    from gsr.reason.hf_backend import compact_answerer
    from gsr.train.compact import CompactSpec, new_model, save
    from gsr.train.evaluate import goal_window

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=128), 0)
    save(model, tok, tmp_path / "w", {}, 3, goal_window=1)
    save(model, tok, tmp_path / "plain", {}, 3)
    assert compact_answerer(str(tmp_path / "w"), model, tok, "cpu").goal_window == 1
    assert compact_answerer(str(tmp_path / "plain"), model, tok, "cpu").goal_window is None
    assert goal_window(tmp_path / "w") == 1 and goal_window(tmp_path / "plain") is None
    marker = tmp_path / "w" / MARKER
    marker.write_text(json.dumps({**json.loads(marker.read_text()), "goal_window": 0}))
    with pytest.raises(BackendError, match="goal_window 0 is not a positive integer"):
        compact_answerer(str(tmp_path / "w"), model, tok, "cpu")


def test_joined_goals_keep_each_conjunct_once_in_order() -> None:
    from gsr.train.longval import joined_goal

    joined = joined_goal("(and (on a b) (in c d))", "(and (in c d) (on e f))")
    assert [str(p) for p in joined.parts] == [
        str(p) for p in parse_formula("(and (on a b) (in c d) (on e f))").parts
    ]
