"""The main job end to end: PyBullet scene, perception, grounding, checked steps, execution, verification."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("pybullet")
pytest.importorskip("open3d")

from gsr.benchmarks.demo import run_demo


def test_demo_verifies_the_goal_and_writes_the_report(tmp_path: Path) -> None:
    """With the simulator's labelled masks (`--oracle-masks`, what `make demo` runs) the goal is verified."""
    out = tmp_path / "demo"
    (out).mkdir()
    (out / "stale.txt").write_text("from an older run")  # replaced whole, never mixed
    assert run_demo(out, seed=0, oracle_masks=True) == 0
    names = {p.name for p in out.iterdir()}
    assert {
        "report.html",
        "plan.txt",
        "summary.json",
        "rgb_before.png",
        "rgb_after.png",
        "graph_before.svg",
        "graph_after.svg",
        "graph_before.json",
        "graph_after.json",
    } <= names
    assert "stale.txt" not in names
    summary = json.loads((out / "summary.json").read_text())
    assert summary["verified"] and summary["perceived"]
    assert [s["step"].split()[0] for s in summary["steps"]] == ["(pick", "(place_in", "(close"]
    assert all(s["executed"] for s in summary["steps"])
    after = json.loads((out / "graph_after.json").read_text())
    edges = {(e["source"], e["relation"], e["target"]) for e in after["edges"]}
    assert ("akita_black_bowl_1", "in", "white_cabinet_1/bottom_drawer") in edges  # remembered, not seen
    html = (out / "report.html").read_text()
    assert "rgb_after.png" in html and "graph_after.svg" in html and "goal verified" in html
    assert not list(tmp_path.glob(".demo-*"))  # no temporary folder left behind


def test_demo_without_the_oracle_acts_on_perceptions_own_nodes(tmp_path: Path) -> None:
    """The default demo perceives from RGB-D alone: it grounds the instruction on perception's own ids and
    the arm acts on the bodies those nodes are. (Whether the goal is then verified depends on the detector:
    docs/performance.md; the test asserts the pipeline, not the detector's accuracy.)"""
    from gsr.perception.detect import load_detector

    if load_detector().model is None:
        pytest.skip("no trained detector weights: the demo uses the labelled masks (tested above)")
    out = tmp_path / "demo"
    code = run_demo(out, seed=0)
    summary = json.loads((out / "summary.json").read_text())
    assert code == (0 if summary["verified"] else 1)
    before = json.loads((out / "graph_before.json").read_text())
    ids = {n["id"] for n in before["nodes"] if not n["attributes"].get("map")}
    assert ids and "akita_black_bowl_1" not in ids and "white_cabinet_1" not in ids  # perception's own ids
    if summary["verdict"].startswith("grounding failed"):  # the detector missed what the instruction names
        assert not summary["steps"] and "no object" in summary["verdict"]
        return
    assert summary["goal"] and "akita_black_bowl_1" not in summary["goal"]
    steps = summary["steps"]
    assert steps and steps[0]["step"].startswith("(pick") and steps[0]["execution"].startswith("ok")


def test_demo_without_a_task_file_is_a_clear_error(tmp_path: Path) -> None:
    from gsr.errors import GSRError

    with pytest.raises(GSRError, match="task file not found"):
        run_demo(tmp_path / "demo", task_path=tmp_path / "missing.bddl")
    assert not (tmp_path / "demo").exists()
