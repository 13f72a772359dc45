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


def test_dependency_order_places_bases_first_and_negative_literals_last() -> None:
    from gsr.reason.compact_decode import dependency_order

    goal = parse_formula(
        "(and (not (open box)) (on spoon plate) (in cube box) (in plate box) (on cup plate) (turned_on lamp))"
    )
    order = [str(p) for p in dependency_order(goal.parts)]
    # (in plate box) moves the plate that two literals put things on: it comes before them; the negative
    # literal comes after every positive one; the rest keep the goal's order
    expected = (
        "(and (in cube box) (in plate box) (on spoon plate) (on cup plate) (turned_on lamp) (not (open box)))"
    )
    assert order == [str(p) for p in parse_formula(expected).parts]
    # a cycle keeps the goal's order
    cycle = parse_formula("(and (on a b) (on b a))")
    assert [str(p) for p in dependency_order(cycle.parts)] == [str(p) for p in cycle.parts]


def test_the_dependency_order_shows_the_base_literal_first(domain, graph) -> None:
    # goal order would show (on cube1 red_box) first, though red_box must go into blue_box before
    goal = parse_formula("(and (on cube1 red_box) (in red_box blue_box) (on cube2 table))")
    shown = window_goal(goal, graph, domain, 1, "dependencies")
    assert [str(p) for p in shown.parts] == [str(parse_formula("(in red_box blue_box)"))]
    assert [str(p) for p in window_goal(goal, graph, domain, 1).parts] == [
        str(parse_formula("(on cube1 red_box)"))
    ]
    with pytest.raises(ValueError, match="goal order 'random'"):
        window_goal(goal, graph, domain, 1, "random")


def test_the_marker_sets_the_goal_order_and_a_bad_one_is_refused(domain, tmp_path) -> None:
    pytest.importorskip("transformers")
    from gsr.errors import GSRError
    from gsr.reason.backend import BackendError
    from gsr.reason.compact import MARKER, build_tokenizer
    from gsr.reason.hf_backend import compact_answerer
    from gsr.train.compact import CompactSpec, new_model, save
    from gsr.train.evaluate import goal_order

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=128), 0)
    save(model, tok, tmp_path / "dep", {}, 3, goal_window=1, goal_order="dependencies")
    save(model, tok, tmp_path / "plain", {}, 3, goal_window=1)
    assert "goal_order" not in json.loads((tmp_path / "plain" / MARKER).read_text())  # old markers unchanged
    assert compact_answerer(str(tmp_path / "dep"), model, tok, "cpu").goal_order == "dependencies"
    assert compact_answerer(str(tmp_path / "plain"), model, tok, "cpu").goal_order == "goal"
    assert goal_order(tmp_path / "dep") == "dependencies" and goal_order(tmp_path / "plain") == "goal"
    marker = tmp_path / "dep" / MARKER
    marker.write_text(json.dumps({**json.loads(marker.read_text()), "goal_order": "random"}))
    with pytest.raises(BackendError, match="goal_order 'random' is not one of goal, dependencies"):
        compact_answerer(str(tmp_path / "dep"), model, tok, "cpu")
    with pytest.raises(GSRError, match="goal_order 'random'"):
        goal_order(tmp_path / "dep")
