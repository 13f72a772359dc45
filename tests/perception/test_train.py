"""Training the no-oracle detector (gsr.perception.train) on a few rendered frames, in seconds."""

from __future__ import annotations

import json

import numpy as np
import pytest
from gsr.perception.detect import RGBDDetector, load_detector, load_model
from gsr.perception.recognize import NONE
from gsr.perception.train import TrainConfig, evaluate, majority, save_model, target_of, train

from gsr.errors import GSRError

pytest.importorskip("pybullet")
pytest.importorskip("torch")

from gsr.benchmarks.perception.render import table_camera

from tests.perception.scenes import FRONT, LEFT, frames, hand_scene

EYES = [(-0.1, 0.0, 0.95), (0.3, 0.7, 0.8), (0.3, -0.7, 0.8), (-0.05, 0.3, 1.0), (0.1, -0.4, 0.9)]


@pytest.fixture(scope="module")
def views():
    scene, _ = hand_scene()
    try:
        return frames(scene, FRONT, LEFT, *(table_camera(e) for e in EYES))
    finally:
        scene.close()


@pytest.fixture(scope="module")
def tiny(views):
    config = TrainConfig(link_frames=2, merge_frames=2, epochs=250, hidden=32, threads=1)
    return train(iter(views), config)


def test_majority_picks_the_covering_truth_id():
    labels = np.array([[0, 0, 1], [0, 1, 1], [-1, 1, 1]])
    truth = np.array([[5, 5, 7], [9, 7, 7], [5, 7, -1]])
    major, share = majority(labels, truth, 2)
    assert major.tolist() == [5, 7]
    assert share[0] == pytest.approx(2 / 3) and share[1] == pytest.approx(0.8)


def test_targets_of_table_and_unlabelled_pixels_are_none(views):
    frame = views[0]
    table = next(k for k, lab in frame.labels.items() if lab.id == "table")
    assert target_of(frame, table) == (NONE, NONE)
    assert target_of(frame, -1) == (NONE, NONE)
    cube = next(k for k, lab in frame.labels.items() if lab.id == "red_cube_1")
    assert target_of(frame, cube) == ("cube", "red")


def test_tiny_model_learns_the_training_scene(views, tiny):
    assert {"cube", "plate", "box", "cabinet"} <= set(tiny.categories)
    result = evaluate(views[3:], {"model": RGBDDetector(tiny), "rules": RGBDDetector(None)})
    assert result["model"]["recall"] >= 0.7
    assert result["model"]["category_accuracy"] >= 0.8
    # learned recognition beats the shape rule on the same segments
    assert result["model"]["category_accuracy"] > result["rules"]["category_accuracy"]


def test_saved_model_reads_back_and_predicts_the_same(views, tiny, tmp_path):
    folder = save_model(tiny, tmp_path / "m")
    assert sorted(p.name for p in folder.iterdir()) == ["MODEL_CARD.md", "model.json", "model.npz"]
    back = load_model(folder)
    x = np.random.default_rng(0).normal(size=(5, tiny.recognize.weights[0][0].shape[1]))
    for a, b in zip(tiny.classify(x), back.classify(x), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-6)
    f = views[0]
    cats = [d.category for d in load_detector(folder).detect(f.rgb, f.depth, f.camera)]
    assert cats[0] == "table" and "cube" in cats
    card = (folder / "MODEL_CARD.md").read_text()
    assert "Where it will not generalise" in card and "Real cameras" in card


def test_broken_model_folders_are_clear_errors(tiny, tmp_path):
    folder = save_model(tiny, tmp_path / "m")
    meta = json.loads((folder / "model.json").read_text())
    meta["features"] = meta["features"][:-1]
    (folder / "model.json").write_text(json.dumps(meta))
    with pytest.raises(GSRError, match="other features"):
        load_model(folder)
    (folder / "model.json").write_text("{not json")
    with pytest.raises(GSRError, match="invalid JSON"):
        load_model(folder)
    (folder / "model.npz").write_bytes(b"garbage")
    (folder / "model.json").write_text(
        json.dumps({**meta, "features": json.loads(json.dumps(meta))["features"]})
    )
    with pytest.raises(GSRError):
        load_model(folder)


def test_training_needs_frames_for_recognition(views):
    with pytest.raises(GSRError, match="more frames"):
        train(iter(views[:2]), TrainConfig(link_frames=1, merge_frames=5, epochs=5))


def test_link_samples_are_the_links_the_model_decides(views):
    """Plain links (no depth step, no colour change) are kept without the model, so they are never
    training rows; the rows carry every link feature, the frame's depth noise included."""
    from gsr.perception.segment import LINK_FEATURE_NAMES, plain_links
    from gsr.perception.train import add_links

    xs, ys = [], []
    add_links(xs, ys, views[0], TrainConfig(link_samples=2000), np.random.default_rng(0))
    x, y = np.concatenate(xs), np.concatenate(ys)
    assert x.shape[1] == len(LINK_FEATURE_NAMES) and len(x) == len(y) > 100
    assert not plain_links(x).any()
    assert 0.0 < y.mean() <= 0.5  # boundaries at most a quarter of the quota, or all there are
    noise = x[:, LINK_FEATURE_NAMES.index("noise")]
    assert np.all(noise == noise[0]) and noise[0] < 2e-4  # one clean rendered frame
