"""`gsr delivery ...` commands: outputs, files and clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from gsr.benchmarks.delivery.building.model import load_building
from typer.testing import CliRunner

from gsr.cli import app

runner = CliRunner()


def test_generate_building(tmp_path: Path) -> None:
    out = tmp_path / "b.json"
    res = runner.invoke(
        app, ["delivery", "generate-building", "--seed", "3", "--floors", "2", "--out", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert "2 floors" in res.output
    assert len(load_building(out).floors) == 2


def test_generate_building_bad_floors(tmp_path: Path) -> None:
    out = tmp_path / "b.json"
    res = runner.invoke(app, ["delivery", "generate-building", "--floors", "0", "--out", str(out)])
    assert res.exit_code == 1 and "floors must be" in res.output
    assert not out.exists()


def test_tasks_and_run(tmp_path: Path) -> None:
    tasks = tmp_path / "t.jsonl"
    res = runner.invoke(app, ["delivery", "tasks", "--split", "val", "--limit", "4", "--out", str(tasks)])
    assert res.exit_code == 0 and len(tasks.read_text().splitlines()) == 4
    res = runner.invoke(app, ["delivery", "tasks", "--split", "test", "--limit", "2"])
    assert res.exit_code == 0 and res.output.startswith("test-0000\t")
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["delivery", "run", "--tasks", str(tasks), "--json", "--out", str(out)])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output)
    assert summary["episodes"] == 4
    assert len(json.loads(out.read_text())["episodes"]) == 4
    res = runner.invoke(app, ["delivery", "run", "--split", "val", "--limit", "2"])
    assert res.exit_code == 0 and "| Task SR |" in res.output


def test_errors() -> None:
    res = runner.invoke(app, ["delivery", "run", "--split", "nope"])
    assert res.exit_code == 1 and "unknown split" in res.output
    res = runner.invoke(app, ["delivery", "run", "--building", "/no/such.json"])
    assert res.exit_code == 1 and "no such file" in res.output
    res = runner.invoke(app, ["delivery", "schedule", "nobody"])
    assert res.exit_code == 1 and "no person" in res.output
    res = runner.invoke(app, ["delivery", "schedule", "Imani", "--seed", "4"])
    assert res.exit_code == 0 and "routine:" in res.output and "actual day" in res.output


def test_map() -> None:
    res = runner.invoke(app, ["delivery", "map", "--floor", "0", "--time", "12:20", "--seed", "3"])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0] == "ground floor at 12:20, world seed 3"
    assert len(lines[1]) == 76 and lines[1] == "#" * 76
    assert any(" = " in line and "(" in line for line in lines[31:])
    res = runner.invoke(app, ["delivery", "map", "--time", "7pm"])
    assert res.exit_code == 1 and "expected HH:MM" in res.output


def test_unsound_building_is_refused(tmp_path: Path) -> None:
    from gsr.benchmarks.delivery.building.shipped import shipped_building_path

    data = json.loads(shipped_building_path().read_text())
    rec = data["receptacles"][0]
    floor = next(r["floor"] for r in data["rooms"] if r["id"] == rec["room"])
    row, col = rec["access"]
    grid = data["floors"][floor]["grid"]
    grid[row] = grid[row][:col] + "#" + grid[row][col + 1 :]  # wall up the access cell
    p = tmp_path / "b.json"
    p.write_text(json.dumps(data))
    res = runner.invoke(app, ["delivery", "run", "--building", str(p), "--limit", "1"])
    assert res.exit_code == 1 and "unusable building" in res.output and rec["id"] in res.output


def test_episode_timeline() -> None:
    res = runner.invoke(app, ["delivery", "episode", "val-0003"])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0].startswith("val-0003 at ")
    assert "parsed: {'object'" in lines[2]
    times = [float(line.split()[0]) for line in lines[3:-1]]
    assert times == sorted(times) and times[-1] <= 480.0
    assert lines[-1].strip().split()[0] in ("SUCCESS", "TIMEOUT", "FAILED")
    res = runner.invoke(app, ["delivery", "episode", "dev-1"])
    assert res.exit_code == 1 and "bad task id" in res.output


def test_documented_command_reproduces_the_shipped_building(tmp_path: Path) -> None:
    from gsr.benchmarks.delivery.building.shipped import shipped_building_path

    out = tmp_path / "three_floor.json"
    res = runner.invoke(
        app, ["delivery", "generate-building", "--seed", "7", "--name", "three-floor", "--out", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert out.read_bytes() == shipped_building_path().read_bytes()
