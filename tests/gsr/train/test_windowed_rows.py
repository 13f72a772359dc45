"""Training rows seen through the decoding's goal window (gsr.train.compact.windowed_samples) and DAgger
rollouts through it: the goal a row shows and the step it is labelled with agree with what decoding shows."""

from __future__ import annotations

import pytest

from gsr.check import check_step
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import And
from gsr.reason.compact import ground_goal
from gsr.reason.compact_decode import window_goal
from gsr.resources import load_builtin_domain
from gsr.semantics import goal_holds, holds

pytest.importorskip("transformers")


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def rows(tmp_path_factory, domain) -> list:
    """Generated rows whose goal has more than one open literal (the rows a window of 1 changes)."""
    from gsr.datagen.runner import RunConfig, generate_dataset
    from gsr.train.compact import dataset_samples

    out = tmp_path_factory.mktemp("windowed") / "ds"
    generate_dataset(RunConfig(out, 1000, seed=5, shard_size=1000), progress=False)
    found = [s for s in dataset_samples(out, "train") if len(_open(domain, s.goal, s.graph)) > 1]
    assert len(found) >= 20
    return found[:20]


def _open(domain, goal, graph) -> list:
    state = state_from_graph(graph, domain)
    grounded = ground_goal(goal, state, domain)
    parts = grounded.parts if isinstance(grounded, And) else (grounded,)
    return [p for p in parts if not holds(domain, p, state)]


def test_a_row_with_more_open_literals_than_the_window_gets_the_window_and_its_planner_step(
    domain, rows
) -> None:
    from gsr.train.compact import Sample, label, windowed_samples

    out = windowed_samples(rows, domain, 1)
    assert len(out) == len(rows)
    relabelled = 0
    for row, shown in zip(rows, out, strict=True):
        assert shown.goal == window_goal(row.goal, row.graph, domain, 1)
        first_open = _open(domain, row.goal, row.graph)[0]
        assert _open(domain, shown.goal, row.graph) == [first_open]  # the first open one, in goal order
        assert (shown.graph, shown.history, shown.source) == (row.graph, row.history, row.source)
        assert shown.answer == label(domain, row.graph, shown.goal)[1]
        relabelled += shown.answer != row.answer
        # following the planner's steps for the shown goal reaches it
        g = row.graph
        for _ in range(12):
            _, step = label(domain, g, shown.goal)
            if step is None:
                break
            g = graph_with_state(g, check_step(domain, state_from_graph(g, domain), step).next_state)
        assert goal_holds(domain, shown.goal, state_from_graph(g, domain))
    assert relabelled  # the whole goal's next step often serves a literal the window hides
    # a row with no more open literals than the window is kept as it is
    done = Sample(rows[0].graph, out[0].goal, rows[0].history, out[0].answer)
    assert windowed_samples([done], domain, 1)[0] is done
    wide = max(len(_open(domain, r.goal, r.graph)) for r in rows)
    assert all(a is b for a, b in zip(windowed_samples(rows, domain, wide), rows, strict=True))


def test_dagger_rollouts_through_the_window_keep_at_most_that_many_open_literals(domain, rows) -> None:
    from gsr.reason.compact import build_tokenizer
    from gsr.train.compact import CompactSpec, label, new_model, rollout_samples

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=256), 0)
    tasks = [(r.graph, r.goal) for r in rows[:3]]
    for constrained in (False, True):
        seen, _ = rollout_samples(
            model, tok, tasks, domain, max_steps=4, version=3, constrained=constrained, goal_window=1
        )
        assert seen
        for r in seen:
            assert len(_open(domain, r.goal, r.graph)) <= 1
            assert r.answer == label(domain, r.graph, r.goal)[1]
        whole, _ = rollout_samples(model, tok, tasks, domain, max_steps=4, version=3, constrained=constrained)
        assert whole[0].goal is tasks[0][1]  # no window: the whole goal, as before
