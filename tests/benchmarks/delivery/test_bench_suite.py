"""`gsr bench run delivery`: the delivery benchmark through the suite runner, agreeing with `gsr delivery run`."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from gsr.benchmarks.cli import run
from gsr.benchmarks.delivery.metrics import EpisodeResult
from typer.testing import CliRunner

from gsr.cli import app
from gsr.errors import GSRError

runner = CliRunner()
WALL = "sim_seconds_per_wall_second"  # the only figure that depends on the machine


def _bench(*args: str) -> dict:
    res = runner.invoke(app, ["bench", "run", "delivery", *args, "--json"])
    assert res.exit_code in (0, 1), res.output  # 1 = not every episode succeeded
    doc = json.loads(res.output)
    assert res.exit_code == (0 if doc["success_rate"] == 1.0 else 1)
    return doc


def test_listed() -> None:
    res = runner.invoke(app, ["bench", "list"])
    assert res.exit_code == 0
    assert "delivery" in res.output and "baseline" in res.output and "no-routines" in res.output


@pytest.mark.parametrize(("split", "agent", "limit"), [("test", "baseline", 16), ("val", "no-routines", 8)])
def test_same_figures_as_delivery_run(tmp_path: Path, split: str, agent: str, limit: int) -> None:
    doc = _bench("--split", split, "--agent", agent, "--limit", str(limit))
    out = tmp_path / "delivery.json"
    res = runner.invoke(
        app,
        [
            "delivery",
            "run",
            "--split",
            split,
            "--agent",
            agent,
            "--limit",
            str(limit),
            "--json",
            "--out",
            str(out),
        ],
    )
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output)
    m = doc["metrics"]
    assert {k: v for k, v in summary.items() if k != WALL} == {k: m[k] for k in summary if k != WALL}
    assert m["episodes"] == limit and doc["success_rate"] == round(summary["task_sr"] / 100, 4)
    # episode by episode, every PRS score agrees too
    episodes = json.loads(out.read_text())["episodes"]
    fields = [k for k in EpisodeResult.model_fields if k != "task"]
    assert [[e["task"], *(e[k] for k in fields)] for e in episodes] == [
        [t["id"], *(t[k] for k in fields)] for t in doc["tasks"]
    ]
    assert json.loads(out.read_text())["breakdown"] == doc["breakdown"]


def test_reports_and_rows(tmp_path: Path) -> None:
    out = tmp_path / "run"
    doc = run("delivery", split="val", limit=6, out=str(out))
    saved = json.loads((out / "results.json").read_text())
    assert saved == json.loads(json.dumps(doc))
    assert saved["suite"] == "delivery" and saved["agent"] == "baseline" and saved["split"] == "val"
    row = saved["tasks"][0]
    for key in ("id", "category", "level", "success", "score", "steps", "reason", "outcome", "world_seed"):
        assert key in row
    assert all(t["score"] == 1.0 for t in saved["tasks"] if t["success"])
    assert sum(saved["metrics"]["outcomes"].values()) == 6
    md = (out / "report.md").read_text()
    assert md.startswith("# Benchmark report: delivery / agent baseline")
    assert "| Task SR |" in md and "| Human-search SR (within 3 m) |" in md
    assert "<pre>" in (out / "report.html").read_text()


def test_workers_and_trials_are_deterministic() -> None:
    one = run("delivery", limit=4, trials=2)
    two = run("delivery", limit=4, trials=2, workers=2)

    assert _strip(one) == _strip(two)
    rows = one["tasks"]
    assert [(t["id"], t["trial"]) for t in rows[:2]] == [("test-0000", 0), ("test-0000", 1)]
    canonical = run("delivery", limit=4)["tasks"]
    # seed 0, trial 0 is each task's own day; trial 1 re-draws it
    assert [t["world_seed"] for t in canonical] == [t["world_seed"] for t in rows if t["trial"] == 0]
    assert all(a["world_seed"] != b["world_seed"] for a, b in zip(rows[::2], rows[1::2], strict=True))
    other = run("delivery", limit=4, seed=5)["tasks"]
    assert [t["world_seed"] for t in other] != [t["world_seed"] for t in canonical]


def test_task_file(tmp_path: Path) -> None:
    tasks = tmp_path / "mine.jsonl"
    res = runner.invoke(app, ["delivery", "tasks", "--split", "val", "--limit", "3", "--out", str(tasks)])
    assert res.exit_code == 0
    doc = _bench("--tasks", str(tasks))
    assert doc["split"] == "mine" and [t["id"] for t in doc["tasks"]] == ["val-0000", "val-0001", "val-0002"]
    split = _bench("--split", "val", "--limit", "3")
    assert _strip(doc) == _strip(split)


def test_errors(tmp_path: Path) -> None:
    cases = [
        (["--agent", "planner"], "unknown agent 'planner'"),
        (["--split", "nope"], "unknown split 'nope'"),
        (["--reference", "lazy-ff"], "does not take --reference"),
        (["--agent-opt", "x=1"], "does not take --agent-opt"),
        (["--source", str(tmp_path / "none.json")], "none.json"),
        (["--limit", "0"], "--limit must be at least 1"),
    ]
    for args, message in cases:
        with pytest.raises(GSRError, match=message):
            run(
                "delivery",
                agent=_opt(args, "--agent"),
                split=_opt(args, "--split"),
                reference=_opt(args, "--reference"),
                agent_options=[a for a in [_opt(args, "--agent-opt")] if a],
                source=_opt(args, "--source"),
                limit=int(_opt(args, "--limit") or 1),
            )
    with pytest.raises(GSRError, match="--split applies to suites with splits"):
        run("rlbench", split="test", limit=1)
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"id": "x"}\n')
    with pytest.raises(GSRError, match=r"bad\.jsonl:1: invalid task"):
        run("delivery", tasks=str(bad))
    res = runner.invoke(app, ["bench", "export", "delivery", "--out", str(tmp_path / "x")])
    assert res.exit_code != 0 and "runs its own episodes" in str(res.exception)
    assert not (tmp_path / "x").exists()


def _strip(doc: dict) -> list[dict]:
    """Episode rows without their measured CPU time."""
    return [{k: v for k, v in t.items() if k != "wall"} for t in doc["tasks"]]


def _opt(args: list[str], name: str) -> str | None:
    return args[args.index(name) + 1] if name in args else None


@pytest.mark.slow
def test_ray_backend_gives_the_same_episodes() -> None:
    pytest.importorskip("ray")
    assert _strip(run("delivery", limit=4, backend="ray")) == _strip(run("delivery", limit=4))
