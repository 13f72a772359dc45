"""The compact model-friendly format: tokens round-trip, goals ground, a compact model loads as a backend."""

from __future__ import annotations

import json
import random

import pytest

from gsr.facts import state_from_graph
from gsr.pddl.parser import parse_formula
from gsr.reason.compact import (
    MARKER,
    CompactError,
    Naming,
    action_tokens,
    answer_step,
    context_tokens,
    goal_tokens,
    query_tokens,
    scene_objects,
    vocabulary,
)
from gsr.step import Step


def test_context_and_answer_round_trip_through_the_word_level_tokenizer(domain, graph, box_goal) -> None:
    pytest.importorskip("transformers")
    from gsr.reason.compact import build_tokenizer

    tok = build_tokenizer(domain)
    state = state_from_graph(graph, domain)
    for seed in range(5):
        naming = Naming.make(scene_objects(state, domain), random.Random(seed))
        history = [Step("pick", ("red_cube1", "table"))]
        tokens = context_tokens(state, domain, box_goal, history, naming)
        ids = tok(" ".join(tokens), add_special_tokens=False)["input_ids"]
        assert tok.convert_ids_to_tokens(ids) == tokens  # one id per word, no unknowns
        assert tok.unk_token_id not in ids
        step = Step("place_in", ("red_cube1", "blue_box"))
        assert answer_step(action_tokens(step, naming), naming, domain) == step
    assert len(tokens) < 60  # the human-readable prompt of this scene is ~1,000 tokens
    assert tokens[0] == "S:" and tokens[-1] == "A:" and "G:" in tokens and "H:" in tokens


def test_naming_hides_names_and_inverts(domain, graph) -> None:
    state = state_from_graph(graph, domain)
    names = scene_objects(state, domain)
    naming = Naming.make(names, random.Random(3))
    assert sorted(naming.to_token.values()) == sorted(f"o{i}" for i in range(len(names)))
    assert {naming.to_name[naming.token(n)] for n in names} == set(names)
    assert naming.token("n0") == "n0"  # domain constants stand for themselves
    inference = Naming.make(names)
    assert inference.to_token == {n: f"o{i}" for i, n in enumerate(sorted(names))}
    with pytest.raises(CompactError, match="objects"):
        Naming.make([f"x{i}" for i in range(100)])


def test_goal_literals_are_marked_true_or_false_and_quantifiers_are_grounded(domain, graph) -> None:
    state = state_from_graph(graph, domain)
    naming = Naming.make(scene_objects(state, domain))
    t = naming.token
    goal = parse_formula("(and (on red_cube1 table) (in red_cube1 blue_box))")
    marked = goal_tokens(goal, state, domain, naming, version=1)
    assert marked == ["G:", "T", "on", t("red_cube1"), t("table"), "F", "in", t("red_cube1"), t("blue_box")]
    # version 2: a literal not holding yet is followed by the facts about its objects
    focus = goal_tokens(goal, state, domain, naming, version=2)
    assert focus[: len(marked)] == marked
    assert focus[len(marked) :] == [":", "on", t("red_cube1"), t("table"), "on", t("blue_box"), t("table")]
    # version 3: also the facts naming the literal's objects later (what stands on or in them), once each
    on_table = [a for a in state.atoms if a.predicate == "on" and a.args[1] == "table"]
    assert len(on_table) >= 2
    v3 = goal_tokens(parse_formula("(not (on red_cube1 table))"), state, domain, naming, version=3)
    assert v3[:6] == ["G:", "F", "not", "on", t("red_cube1"), t("table")] and v3[6] == ":"
    facts = [tuple(v3[i : i + 3]) for i in range(7, len(v3), 3)]
    assert len(facts) == len(set(facts)) == (len(v3) - 7) // 3
    for atom in on_table:  # every object standing on the table is named after the literal
        assert ("on", t(atom.args[0]), t(atom.args[1])) in facts
    v2 = goal_tokens(parse_formula("(not (on red_cube1 table))"), state, domain, naming, version=2)
    assert len(v2) < len(v3)
    # every red cube in the box: the colour test is static, so it is evaluated away
    forall = parse_formula("(forall (?x - cube) (imply (has_color ?x red) (in ?x blue_box)))")
    assert goal_tokens(forall, state, domain, naming, 1) == ["G:", "F", "in", t("red_cube1"), t("blue_box")]


def test_unknown_answers_are_compact_errors(domain, graph) -> None:
    _, naming = query_tokens(graph, domain, None, ())
    assert answer_step(["done", "<eos>"], naming, domain) is None
    with pytest.raises(CompactError, match="not an action"):
        answer_step(["o1", "o2"], naming, domain)
    with pytest.raises(CompactError, match="unknown object"):
        answer_step(["pick", "o63", "o0"], naming, domain)


def test_vocabulary_covers_the_domain(domain) -> None:
    words = vocabulary(domain)
    assert len(words) == len(set(words))
    assert set(domain.actions) <= set(words) and set(domain.predicates) <= set(words)


@pytest.fixture(scope="module")
def compact_folder(tmp_path_factory, domain):
    pytest.importorskip("transformers")
    from gsr.reason.compact import build_tokenizer
    from gsr.train.compact import CompactSpec, new_model, save

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=32, layers=1, heads=2, intermediate=64, context=256), 0)
    out = tmp_path_factory.mktemp("compact") / "model"
    save(model, tok, out, {"test": True})
    return out


def test_constrained_compact_backend_answers_only_admissible_lines(
    compact_folder, domain, graph, box_goal
) -> None:
    from gsr.reason.applicable import applicable_steps
    from gsr.reason.backend import Query
    from gsr.reason.hf_backend import TransformersBackend
    from gsr.reason.prompt import build_prompt
    from gsr.reason.step_format import format_step

    backend = TransformersBackend(str(compact_folder))
    prompt = build_prompt(graph, domain, "put the red cube in the blue box", examples=())
    allowed = tuple(format_step(s) for s in applicable_steps(domain, graph))
    query = Query("step", prompt, graph, domain, "", box_goal, (), allowed)
    first = backend.complete(prompt, (), query)
    assert first in allowed
    # a rejected answer is not given again: the next best admissible line comes instead
    again = backend.complete(
        prompt, (), Query("step", prompt, graph, domain, "", box_goal, (), allowed, (first,))
    )
    assert again in allowed and again != first
    free = backend.complete(prompt, (), Query("step", prompt, graph, domain, "", box_goal, ()))
    assert isinstance(free, str)


def test_compact_backend_errors_are_clear(compact_folder, tmp_path, domain, graph) -> None:
    import shutil

    from gsr.reason.backend import BackendError, Query
    from gsr.reason.hf_backend import TransformersBackend
    from gsr.reason.prompt import build_goal_prompt

    backend = TransformersBackend(str(compact_folder))
    prompt = build_goal_prompt(graph, domain, "tidy up", examples=())
    with pytest.raises(BackendError, match="step queries only"):
        backend.complete(prompt, (), Query("goal", prompt, graph, domain, "tidy up"))
    with pytest.raises(BackendError, match="step queries only"):
        backend.complete(prompt)
    bad = tmp_path / "bad"
    shutil.copytree(compact_folder, bad)
    (bad / MARKER).write_text(json.dumps({"format": "gsr-compact-0"}))
    with pytest.raises(BackendError, match="retrain"):
        TransformersBackend(str(bad))
    (bad / MARKER).write_text("{not json")
    with pytest.raises(BackendError, match="unreadable"):
        TransformersBackend(str(bad))


def test_constrained_loop_takes_the_least_visited_successor(compact_folder, domain, graph) -> None:
    """Under constrained decoding even an untrained model executes only valid steps, and every step goes
    to a successor state visited least often so far (never back while an unvisited one exists)."""
    from collections import Counter

    from gsr.check import check_step
    from gsr.facts import graph_with_state
    from gsr.reason import solve
    from gsr.reason.applicable import applicable_steps
    from gsr.reason.hf_backend import TransformersBackend
    from gsr.step import Goal

    backend = TransformersBackend(str(compact_folder))
    goal = Goal(parse_formula("(and (in red_cube1 blue_box) (open short_cabinet/drawer_low))"), "x")
    result = solve(graph, "x", backend, domain=domain, goal=goal, max_steps=12, constrained=True)
    assert result.steps and result.rejections == 0
    visits = Counter([state_from_graph(graph, domain).atoms])
    current = graph
    for s in result.steps:
        state = state_from_graph(current, domain)
        options = [
            visits[check_step(domain, state, a).next_state.atoms] for a in applicable_steps(domain, current)
        ]
        diagnosis = check_step(domain, state, s.step)
        assert diagnosis.ok
        assert visits[diagnosis.next_state.atoms] == min(options)
        current = graph_with_state(current, diagnosis.next_state)
        visits[state_from_graph(current, domain).atoms] += 1
