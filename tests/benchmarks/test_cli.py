"""`gsr bench ...`: list, run (reports, exit codes, errors), export and re-run exported tasks."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from gsr.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_bench_list() -> None:
    result = runner.invoke(app, ["bench", "list"])
    assert result.exit_code == 0
    for name in ("gsr-bench", "gsr-bench-gen", "libero", "rlbench", "tasks", "planner", "random", "reasoner"):
        assert name in result.output


def test_bench_run_writes_reports(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(app, ["bench", "run", "rlbench", "--limit", "4", "--out", str(out)])
    assert result.exit_code == 0, result.output
    doc = json.loads((out / "results.json").read_text())
    assert doc["suite"] == "rlbench" and doc["agent"] == "planner" and doc["success_rate"] == 1.0
    assert len(doc["tasks"]) == 4
    assert (out / "report.md").read_text().startswith("# Benchmark report: rlbench")
    assert (out / "report.html").exists()


def test_bench_run_json_and_failure_exit() -> None:
    args = ["bench", "run", "tasks", "--tasks", str(REPO / "data" / "tasks" / "examples")]
    result = runner.invoke(app, [*args, "--agent", "random", "--max-steps", "3", "--json"])
    assert result.exit_code == 1  # not every episode succeeded
    doc = json.loads(result.output)
    assert doc["tasks"][0]["outcome"] == "planning_error" and doc["tasks"][0]["steps"] == 3
    ok = runner.invoke(app, [*args])
    assert ok.exit_code == 0 and "success 100.0%" in ok.output


def test_bench_errors_are_one_line(tmp_path: Path) -> None:

    result = runner.invoke(app, ["bench", "run", "nosuch"])
    assert result.exit_code != 0 and "unknown suite 'nosuch'" in str(result.exception)
    bad = tmp_path / "bad.json"
    bad.write_text('{"id": "x", "suite": "s", "instructions": [], "initial": {"nodes": []}, "goal": "(and"}')
    result = runner.invoke(app, ["bench", "run", "tasks", "--tasks", str(bad)])
    assert result.exit_code != 0
    msg = str(result.exception)
    assert "bad.json: invalid task" in msg and "instructions" in msg and "goal" in msg
    result = runner.invoke(app, ["bench", "run", "libero", "--source", str(tmp_path / "none")])
    assert "does not exist" in str(result.exception)


def test_export_then_run_exported(tmp_path: Path) -> None:
    result = runner.invoke(
        app, ["bench", "export", "rlbench", "--out", str(tmp_path / "tasks"), "--seed", "2"]
    )
    assert result.exit_code == 0 and "wrote 100 task(s)" in result.output
    files = sorted((tmp_path / "tasks").glob("*.json"))
    assert len(files) == 100
    result = runner.invoke(app, ["bench", "run", "tasks", "--tasks", str(files[0]), "--json"])
    assert result.exit_code == 0 and json.loads(result.output)["tasks"][0]["id"] == files[0].stem
