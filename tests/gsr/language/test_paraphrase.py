"""The paraphrase benchmark (data/language/paraphrase_*.yaml), goal equivalence, the fallback route."""

from __future__ import annotations

import pytest

from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.language import GroundingError, ground
from gsr.language.measure import run_items
from gsr.language.paraphrase import PARTS, load_items, same_goal_states, scene_graph
from gsr.pddl.parser import parse_formula
from gsr.plan import plan_graph
from gsr.transition import apply_steps
from tests.gsr.language.conftest import ground_dnf
from tests.gsr.language.scene_fixture import scene


@pytest.fixture(scope="module")
def items(shared_data) -> dict[str, list]:
    return {part: load_items(part) for part in PARTS}


def test_suite_size_and_parts(items) -> None:
    n_dev, n_held = len(items["dev"]), len(items["heldout"])
    assert n_dev + n_held >= 300
    assert 0.25 <= n_held / (n_dev + n_held) <= 0.35
    says = [i.say for part in PARTS for i in items[part]]
    assert len(set(says)) >= 0.95 * len(says)  # varied wording, few repeats across scenes


def test_every_reference_is_a_satisfiable_goal_on_its_scene(items) -> None:
    for part in PARTS:
        for item in items[part]:
            graph = scene_graph(item.scene)
            dnf = ground_dnf(parse_formula(item.goal, item.say), graph)
            assert dnf, f"{item.say!r}: the reference goal is unsatisfiable on {item.scene}"


def test_development_part_at_least_95_percent(items) -> None:
    outcomes = [kind for _, kind, _ in run_items(items["dev"])]
    assert outcomes.count("equivalent") / len(outcomes) >= 0.95


def test_same_goal_states_knows_one_place_at_a_time() -> None:
    g = scene()
    a = parse_formula("(in milk red_box)", "a")
    b = parse_formula("(and (in milk red_box) (not (in milk blue_box)))", "b")
    c = parse_formula("(in milk blue_box)", "c")
    assert ground_dnf(a, g) != ground_dnf(b, g)  # different formulas ...
    assert same_goal_states(a, b, g)  # ... same states: the milk cannot be in two boxes
    assert not same_goal_states(a, c, g)
    exact = parse_formula(
        "(or (and (in red_cube1 red_box) (not (in red_cube2 red_box))) "
        "(and (in red_cube2 red_box) (not (in red_cube1 red_box))))",
        "exact",
    )
    assert same_goal_states(ground("put one red cube in the red box", g).formula, exact, g)


def test_counts_are_exact() -> None:
    g = scene()
    dnf = ground_dnf(ground("put 2 red cubes in the yellow box", g).formula, g)
    assert len(dnf) == 1  # the two red cubes: both, nothing to choose
    with pytest.raises(GroundingError, match="only 2"):
        ground("put three red cubes in the yellow box", g)
    dnf = ground_dnf(ground("put a couple of the cubes in the yellow box", g).formula, g)
    assert len(dnf) == 6  # 2 of 4 cubes
    assert all(sum(v for _, v in conj) == 2 for conj in dnf)


def test_exceptions_and_everything() -> None:
    g = scene()
    goal = ground("put everything except the cubes into the yellow box", g)
    placed = {a.args[0] for conj in ground_dnf(goal.formula, g) for a, v in conj if v}
    assert placed == {"red_mug1", "blue_mug1", "milk", "popcorn", "yellow_book"}  # no boxes, no cubes


def test_take_them_out_and_put_them_in_ends_with_the_hand_empty() -> None:
    message = {
        "nodes": ["table", "red_box", "blue_box", "milk", "popcorn"],
        "edges": ["red_box(on)table", "blue_box(on)table", "milk(in)blue_box", "popcorn(in)blue_box"],
    }
    g = graph_from_gsr_bench(message)
    goal = ground("take the milk and the popcorn out of the blue box and put them in the red box", g)
    result = plan_graph(None, g, goal, timeout=60)
    assert result.solved
    final = apply_steps(g, result.plan.steps)[-1]
    assert not any(e.relation == "holding" for e in final.edges)
    assert {(e.source, e.relation, e.target) for e in final.edges} >= {
        ("milk", "in", "red_box"),
        ("popcorn", "in", "red_box"),
    }


def test_fallback_matches_an_unknown_verb_when_the_rest_is_clear() -> None:
    g = scene()
    goal = ground("kindly nudge the popcorn into the yellow box", g)
    assert [a for conj in ground_dnf(goal.formula, g) for a in conj] == [
        (parse_formula("(in popcorn yellow_box)", "x"), True)
    ]


def test_unclear_words_give_a_clarifying_error_with_suggestions() -> None:
    g = scene()
    with pytest.raises(GroundingError) as err:
        ground("jiggle the yelow cube into the red box", g)
    assert err.value.unknown_words == ("jiggle", "yelow")
    assert "yellow" in err.value.suggestions["yelow"]
    assert "did you mean" in err.value.message
    with pytest.raises(GroundingError):  # negation: never guessed over
        ground("do not wiggle the milk into the red box", g)
