"""plan() keeps the cyclic collector off grounding's objects and leaves the collector as it found it."""

from __future__ import annotations

import gc

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.plan import api, plan_graph
from gsr.resources import load_builtin_domain


@pytest.fixture
def task():
    _, graph, goal, _ = long_tabletop_task(0)
    return load_builtin_domain("tabletop"), graph, goal


def test_search_runs_with_grounding_frozen_and_collector_restored(task, monkeypatch) -> None:
    seen = []
    real = api.Relaxation  # built once per plan(), right after grounding, for the reachability check

    def spy(*args, **kwargs):
        seen.append((gc.isenabled(), gc.get_freeze_count()))
        return real(*args, **kwargs)

    monkeypatch.setattr(api, "Relaxation", spy)
    before = gc.get_freeze_count()
    result = plan_graph(*task)
    assert result.status == "solved"
    enabled, frozen = seen[0]
    assert enabled and frozen > before  # the grounded task (and what was alive) is frozen for the search
    assert gc.isenabled() and gc.get_freeze_count() == before == 0


def test_a_disabled_collector_stays_disabled_and_nothing_is_frozen(task) -> None:
    gc.disable()
    try:
        assert plan_graph(*task).status == "solved"
        assert not gc.isenabled() and gc.get_freeze_count() == 0
    finally:
        gc.enable()


def test_collector_restored_when_the_search_raises(task, monkeypatch) -> None:
    def boom(*args, **kwargs):
        raise RuntimeError("search failed")

    monkeypatch.setattr(api, "Relaxation", boom)
    with pytest.raises(RuntimeError):
        plan_graph(*task)
    assert gc.isenabled() and gc.get_freeze_count() == 0
