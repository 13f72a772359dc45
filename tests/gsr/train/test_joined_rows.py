"""Longer training tasks (the recipe's ``joined_tasks``): two train goals of one scene joined
(gsr.train.longval.long_tasks on the train split) and the planner's episodes on them as rows
(gsr.train.compact.planner_samples), seen through the goal window as decoding sees them."""

from __future__ import annotations

import pytest

from gsr.check import check_step
from gsr.datagen.tasks import generated_tasks
from gsr.errors import GSRError
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import And
from gsr.pddl.parser import parse_formula
from gsr.reason.compact import ground_goal
from gsr.reason.compact_decode import window_goal
from gsr.resources import load_builtin_domain
from gsr.semantics import goal_holds, holds
from gsr.train.longval import long_tasks


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    from gsr.datagen.runner import RunConfig, generate_dataset

    out = tmp_path_factory.mktemp("joined") / "ds"
    generate_dataset(RunConfig(out, 1000, seed=5, shard_size=1000), progress=False)
    return out


@pytest.fixture(scope="module")
def joined(data):
    return long_tasks(data, 4, 0, min_plan=5, split="train", timeout=2.0)


def _open(domain, goal, graph) -> list:
    state = state_from_graph(graph, domain)
    grounded = ground_goal(goal, state, domain)
    parts = grounded.parts if isinstance(grounded, And) else (grounded,)
    return [p for p in parts if not holds(domain, p, state)]


def test_joined_training_tasks_come_from_the_train_split_only_and_repeat_per_seed(data, joined) -> None:
    assert len(joined) == 4
    train = {t.id: t for t in generated_tasks(data, "train")}
    others = set()
    for split in ("val", "test"):
        if list((data / "data" / split).glob("*.jsonl")):  # a small dataset may have none
            others |= {t.id for t in generated_tasks(data, split)}
    assert others
    for t in joined:
        a, b = t.metadata["from"]
        assert a in train and b in train and a not in others and b not in others
        assert t.initial == train[a].initial
        assert t.category == "long-train" and t.metadata["plan"] >= 5
        # the conjunction of both goals: more literals than either
        parts = parse_formula(t.goal).parts
        for x in (a, b):
            assert set(parse_formula(train[x].goal).parts) <= set(parts)
    again = long_tasks(data, 4, 0, min_plan=5, split="train", timeout=2.0)
    assert [t.id for t in again] == [t.id for t in joined]
    assert [t.goal for t in again] == [t.goal for t in joined]
    other = long_tasks(data, 4, 1, min_plan=5, split="train", timeout=2.0)
    assert [t.id for t in other] != [t.id for t in joined]


def test_joined_tasks_never_read_the_test_split(data) -> None:
    with pytest.raises(GSRError, match="val or train"):
        long_tasks(data, 2, 0, split="test")


def test_planner_rows_follow_the_planner_through_the_window_to_the_whole_goal(domain, joined) -> None:
    from gsr.train.compact import label, planner_samples

    for t in joined:
        goal = parse_formula(t.goal)
        rows = planner_samples([(t.initial, goal)], domain, 1, "dependencies")
        assert len(rows) >= 2
        graph = t.initial
        for i, row in enumerate(rows):
            assert row.source == "joined" and row.graph == graph and len(row.history) == i
            assert row.goal == window_goal(goal, graph, domain, 1, "dependencies")
            assert len(_open(domain, row.goal, graph)) <= 1
            assert row.answer == label(domain, graph, row.goal)[1]
            if row.answer is None:
                break
            diagnosis = check_step(domain, state_from_graph(graph, domain), row.answer)
            assert diagnosis.ok
            graph = graph_with_state(graph, diagnosis.next_state)
        # the episode ends with a done row where the whole goal holds
        assert rows[-1].answer is None and i == len(rows) - 1
        assert goal_holds(domain, goal, state_from_graph(rows[-1].graph, domain))
    # without a window every row shows the whole goal
    t = joined[0]
    whole = planner_samples([(t.initial, parse_formula(t.goal))], domain)
    assert all(r.goal == parse_formula(t.goal) for r in whole)
    assert whole[-1].answer is None and all(r.answer is not None for r in whole[:-1])
    assert goal_holds(domain, parse_formula(t.goal), state_from_graph(whole[-1].graph, domain))
    # joined goals open more literals at the start than the window shows
    assert any(len(_open(domain, parse_formula(x.goal), x.initial)) > 1 for x in joined)
