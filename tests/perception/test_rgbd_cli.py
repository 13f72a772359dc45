"""`gsr perceive` without masks: RGB + depth + camera only, several cameras, tracking, and bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gsr.scene_graph import SceneGraph

pytest.importorskip("pybullet")
pytest.importorskip("open3d")

from gsr.benchmarks.perception.render import save_frame

from tests.perception.scenes import FRONT, LEFT, frames, hand_scene


@pytest.fixture(scope="module")
def views(tmp_path_factory) -> list[dict[str, Path]]:
    """Two rendered cameras written as the files a user passes (masks and labels are not used)."""
    scene, _ = hand_scene()
    try:
        rendered = frames(scene, FRONT, LEFT)
    finally:
        scene.close()
    out = []
    for k, frame in enumerate(rendered):
        d = tmp_path_factory.mktemp(f"view{k}")
        out.append({name.split(".")[0]: path for name, path in save_frame(frame, d).items()})
    return out


def _gsr(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "gsr.cli", *args], capture_output=True, text=True, timeout=300, check=False
    )


def _view_args(*vs: dict[str, Path], **override: Path) -> list[str]:
    out: list[str] = []
    for v in vs:
        f = {**v, **override}
        out += ["--rgb", str(f["rgb"]), "--depth", str(f["depth"]), "--camera", str(f["camera"])]
    return out


def test_perceive_without_masks_from_two_cameras_and_with_a_previous_graph(views, tmp_path):
    out = tmp_path / "graph.json"
    res = _gsr("perceive", *_view_args(*views), "--out", str(out))
    assert res.returncode == 0, res.stderr
    graph = SceneGraph.load(out)
    assert graph.metadata["frames"] == 2 and len(graph.nodes) >= 5
    for n in graph.nodes:  # ids are perception's own: <category>_<k> or <parent>/<category>_<k>
        assert n.id.rsplit("/", 1)[-1].rsplit("_", 1)[0] == n.category, n.id
    assert any(e.relation == "on" for e in graph.edges)
    # the same scene again, with the first graph as the previous one: the ids carry over
    again = tmp_path / "again.json"
    res = _gsr("perceive", *_view_args(views[0]), "--previous", str(out), "--out", str(again))
    assert res.returncode == 0, res.stderr
    second = SceneGraph.load(again)
    seen = {n.id for n in second.nodes if n.attributes.get("observed", True) is not False}
    carried = seen & {n.id for n in graph.nodes}
    assert seen and len(carried) >= 0.7 * len(seen), (seen, carried)  # one camera may see a piece more


def test_missing_depth_mismatched_sizes_and_stray_labels_are_one_line_errors(views, tmp_path):
    v = views[0]
    res = _gsr("perceive", "--rgb", str(v["rgb"]), "--camera", str(v["camera"]))
    assert res.returncode == 1 and "one --depth per --rgb" in res.stderr
    small = tmp_path / "small.npy"
    np.save(small, np.ones((10, 12), np.float32))
    res = _gsr("perceive", *_view_args(v, depth=small))
    assert res.returncode == 1 and "sizes differ" in res.stderr
    res = _gsr("perceive", *_view_args(v), "--labels", str(v["labels"]))
    assert res.returncode == 1 and "--labels needs --masks" in res.stderr
    res = _gsr("perceive", *_view_args(*views), "--masks", str(v["masks"]))
    assert res.returncode == 1 and "exactly one" in res.stderr
    for r in (res,):
        assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_nan_and_empty_depth_give_a_graph_not_a_crash(views, tmp_path):
    v = views[0]
    depth = np.load(v["depth"])
    holes = tmp_path / "holes.npy"
    d = depth.copy()
    d[::7] = np.nan
    d[:, ::11] = np.inf
    np.save(holes, d)
    res = _gsr("perceive", *_view_args(v, depth=holes))
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["nodes"]
    blank = tmp_path / "blank.npy"
    np.save(blank, np.zeros_like(depth))
    res = _gsr("perceive", *_view_args(v, depth=blank))
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout).get("nodes", []) == []  # an empty graph (its JSON omits empty fields)
