"""``gsr ground``: goal as PDDL or JSON, exit 1 with the grounding error."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

from gsr.cli import app
from tests.gsr.language.scene_fixture import MESSAGE


def _scene(tmp_path: Path) -> Path:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(MESSAGE), encoding="utf-8")
    return path


def test_prints_pddl(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["ground", "--scene", str(_scene(tmp_path)), "open the bottom drawer"])
    assert result.exit_code == 0
    assert result.stdout.strip() == "(and (open short_cabinet/drawer_low))"


def test_json_output(tmp_path: Path) -> None:
    result = CliRunner().invoke(
        app, ["ground", "put all red cubes in the blue box", "--scene", str(_scene(tmp_path)), "--json"]
    )
    assert result.exit_code == 0
    data = json.loads(result.stdout)
    assert data["goal"] == "(and (forall (?x - cube) (imply (has_color ?x red) (in ?x blue_box))))"
    assert data["instruction"] == "put all red cubes in the blue box"


def test_grounding_error_exits_1(tmp_path: Path) -> None:
    result = CliRunner().invoke(
        app, ["ground", "put the red cube in the blue box", "--scene", str(_scene(tmp_path)), "--json"]
    )
    assert result.exit_code == 1
    data = json.loads(result.stdout)
    assert data["candidates"] == ["red_cube1", "red_cube2"]


def test_libero_bddl_scene(libero_dir: Path) -> None:
    bddl = libero_dir / "libero_goal" / "turn_on_the_stove.bddl"
    result = CliRunner().invoke(app, ["ground", "--scene", str(bddl), "turn on the stove"])
    assert result.exit_code == 0 and "(turned_on flat_stove_1)" in result.stdout


def test_bad_scene_file_is_one_line(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "gsr.cli", "ground", "--scene", str(tmp_path / "missing.json"), "open it"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 1
    assert proc.stderr.strip() == f"error: {tmp_path / 'missing.json'}: no such file"
