"""Exported generated tasks: valid TaskSpec files the suites runner can load and a planner can solve."""

from __future__ import annotations

from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.datagen.tasks import export_tasks
from gsr.plan.api import plan_graph
from gsr.resources import load_builtin_domain
from gsr.task_spec import load_task


def test_export_test_tasks_round_trip_and_are_solvable(tmp_path) -> None:
    data = tmp_path / "ds"
    generate_dataset(RunConfig(data, 2500, seed=5, shard_size=2500), progress=False)
    out = tmp_path / "tasks"
    n = export_tasks(data, out, split="test", limit=6)
    files = sorted(out.glob("*.json"))
    assert n == len(files) > 0
    domain = load_builtin_domain()
    for f in files:
        task = load_task(f)
        assert task.category in ("pair", "color", "horizon") and task.instruction
        result = plan_graph(domain, task.initial, task.goal_formula(), timeout=20)
        assert result.solved and len(result.plan) >= 1
