"""GenManip-style scoring: best alternative's fraction of satisfied relations, beside strict success."""

from __future__ import annotations

from gsr.benchmarks.scoring import score_task
from gsr.benchmarks.suites.builder import SceneBuilder

from gsr.facts import state_from_graph
from gsr.task_spec import TaskSpec


def _task(goal: str, alternatives: tuple[str, ...] = ()) -> tuple[TaskSpec, SceneBuilder]:
    b = SceneBuilder(seed=0)
    b.add("red_box", "box", color="red")
    b.add("blue_box", "box", color="blue")
    b.add("c1", "cube", color="red", inside="red_box")
    b.add("c2", "cube", color="red", inside="blue_box")
    b.add("c3", "cube", color="red")
    t = TaskSpec(
        id="t", suite="s", instructions=("x",), initial=b.graph(), goal=goal, goal_alternatives=alternatives
    )
    return t, b


def test_partial_credit_and_best_alternative(domain) -> None:
    t, _ = _task(
        "(and (in c1 red_box) (in c2 red_box) (in c3 red_box))",
        (
            "(and (in c1 blue_box) (in c2 blue_box) (in c3 blue_box))",
            "(and (in c1 red_box) (in c2 blue_box))",
        ),
    )
    s = score_task(domain, t, state_from_graph(t.initial, domain))
    assert s.success and s.score == 1.0 and s.best == 2  # the third alternative holds
    t2, _ = _task(
        "(and (in c1 red_box) (in c2 red_box) (in c3 red_box))",
        ("(and (in c1 blue_box) (in c2 blue_box) (in c3 blue_box))",),
    )
    s2 = score_task(domain, t2, state_from_graph(t2.initial, domain))
    assert not s2.success
    assert s2.score == round(1 / 3, 6) and s2.satisfied == 1 and s2.total == 3
    assert s2.recall == round(1 / 3, 6)


def test_non_conjunctive_goal_is_one_relation(domain) -> None:
    t, _ = _task("(or (in c3 red_box) (in c3 blue_box))")
    s = score_task(domain, t, state_from_graph(t.initial, domain))
    assert not s.success and s.score == 0.0 and s.total == 1
    t, _ = _task("(forall (?x - cube) (imply (has_color ?x red) (not (on ?x table))))")
    s = score_task(domain, t, state_from_graph(t.initial, domain))
    assert not s.success and s.total == 1
