"""Prompt builder: scene, actions, instruction, history, rejected attempts, a checked example."""

from __future__ import annotations

import pytest

from gsr.facts import state_from_graph
from gsr.graph_text import to_prompt_text
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.reason import annotate_steps, build_goal_prompt, build_prompt, builtin_example, parse_steps
from gsr.resources import load_builtin_domain
from gsr.step import Step
from gsr.validate import validate_plan

SCENE = {
    "nodes": ["table", "blue_box", "red_cube1", "short_cabinet", "short_cabinet/drawer_low(closed)"],
    "edges": ["blue_box(on)table", "red_cube1(on)table", "short_cabinet(on)table"],
}


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def graph():
    return graph_from_gsr_bench(SCENE)


def test_steps_prompt_layout(domain, graph):
    prompt = build_prompt(
        graph,
        domain,
        "put the red cube in the blue box",
        history=[Step("open", ("short_cabinet/drawer_low",))],
        rejected=[("(pick red_cube1 blue_box)", "precondition (on red_cube1 blue_box) is false")],
    )
    assert to_prompt_text(graph) in prompt.user
    assert "(hand_empty)" in prompt.user and "(cube_count blue_box n0)" in prompt.user
    assert "Instruction: put the red cube in the blue box" in prompt.user
    assert "Steps so far:\n(open short_cabinet/drawer_low)" in prompt.user
    assert "rejected: precondition (on red_cube1 blue_box) is false" in prompt.user
    for name in domain.actions:
        assert f"({name} " in prompt.system
    assert prompt.text().endswith("Next step:\n")
    assert [m["role"] for m in prompt.messages()] == ["system", "user"]
    # no examples on request; signatures only on request
    bare = build_prompt(graph, domain, "x", examples=(), actions="signatures")
    assert "Example" not in bare.system and "pre:" not in bare.system


def test_builtin_example_is_a_valid_checked_solution(domain):
    example = builtin_example(domain)
    steps = parse_steps("\n".join(example.steps))
    assert all(s.claims_effects for s in steps)
    graph = graph_from_gsr_bench(
        {
            "nodes": [
                "table",
                "green_box",
                "yellow_cube1",
                "small_cabinet",
                "small_cabinet/drawer_top(closed)",
            ],
            "edges": ["green_box(on)table", "yellow_cube1(in)green_box", "small_cabinet(on)table"],
        }
    )
    from gsr.pddl.parser import parse_formula

    report = validate_plan(domain, state_from_graph(graph, domain), steps, parse_formula(example.goal))
    assert report.valid, str(report)


def test_annotate_steps_claims_exactly_the_true_change(domain, graph):
    (pick,) = annotate_steps(domain, graph, [Step("pick", ("red_cube1", "table"))])
    assert {str(a) for a in pick.add} == {"(holding red_cube1)"}
    assert {str(a) for a in pick.delete} == {"(hand_empty)", "(on red_cube1 table)"}


def test_goal_prompt(domain, graph):
    prompt = build_goal_prompt(graph, domain, "put the red cube in the box", rejected=[("(in x)", "bad")])
    assert "(cube_count ?c - thing ?n - count)" in prompt.system
    assert "Goal:\n(and (in yellow_cube1" in prompt.system
    assert prompt.user.endswith("Goal:") and "rejected: bad" in prompt.user
