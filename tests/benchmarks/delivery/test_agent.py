"""The baseline agent on a small subset, and the summary arithmetic."""

from __future__ import annotations

import pytest
from gsr.benchmarks.delivery.metrics import EpisodeResult, summarize, summary_table
from gsr.benchmarks.delivery.run import run_split
from gsr.benchmarks.delivery.tasks import generate_tasks


def test_baseline_on_a_subset(shipped) -> None:
    out = run_split(shipped, "val", limit=25)
    assert len(out.results) == 25
    for r in out.results:
        assert 0 < r.time <= 480.0
        if r.success:
            assert r.grasped and r.object_found and r.person_within_3m and r.person_within_5m
            assert not r.timed_out
        if r.grasped:
            assert r.object_found
        if r.person_within_3m:
            assert r.person_within_5m
    s = out.summary
    assert s.episodes == 25 and s.parsing_accuracy == 100.0
    assert s.task_sr >= 60.0  # measured ~90%; a large drop means the agent or world broke
    assert s.sim_seconds_per_wall_second > 10  # simulated time runs much faster than real time
    again = run_split(shipped, "val", limit=25)
    assert [r.model_dump(exclude={"time"}) for r in again.results] == [
        r.model_dump(exclude={"time"}) for r in out.results
    ]


def test_unparseable_instruction_fails_cleanly(shipped) -> None:
    from gsr.benchmarks.delivery.run import run_tasks

    task = generate_tasks(shipped, "val", limit=1)[0].model_copy(update={"instruction": "Sing a song."})
    out = run_tasks(shipped, [task])
    r = out.results[0]
    assert not r.success and not r.parse_correct and "cannot parse" in r.note


def test_summary_numbers() -> None:
    def ep(i: int, success: bool, grasp: bool, near: bool, t: float) -> EpisodeResult:
        return EpisodeResult(
            task=f"t{i}", success=success, parse_correct=True, object_found=grasp, grasped=grasp,
            person_within_5m=near, person_within_3m=near and success, timed_out=not success,
            time=t, metres=0.0, actions=1,
        )  # fmt: skip

    s = summarize("x", [ep(0, True, True, True, 100), ep(1, False, True, True, 480), ep(2, False, False, False, 480),
                        ep(3, True, True, True, 200)], wall_seconds=2.0)  # fmt: skip
    assert s.task_sr == 50.0 and s.manipulation_sr == 75.0 and s.human_search_sr == 50.0
    assert s.human_within_5m == 75.0 and s.timeouts == 50.0
    assert s.mean_time == 315.0 and s.mean_time_success == 150.0
    assert s.sim_seconds_per_wall_second == 630.0
    assert "| Task SR | 50.0% |" in summary_table(s)


def test_breakdown_groups_every_episode(shipped) -> None:
    from gsr.benchmarks.delivery.metrics import breakdown, breakdown_table

    out = run_split(shipped, "val", limit=12)
    rows = breakdown(out.tasks, out.results)
    facets = {r["facet"] for r in rows}
    assert facets == {"object described by", "recipient referred to by", "recipient's room given"}
    for facet in facets:
        assert sum(r["episodes"] for r in rows if r["facet"] == facet) == 12
    assert "| recipient's room given |" in breakdown_table(rows)
    with pytest.raises(ValueError, match="same episodes"):
        breakdown(out.tasks[1:], out.results[:-1])
