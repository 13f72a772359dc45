"""No-oracle detection (gsr.perception.detect): instances from RGB + depth + camera, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from gsr.perception.detect import Detection, Detector, RGBDDetector, load_detector
from gsr.perception.segment import SegmentParams, segment

from gsr.errors import GSRError

pytest.importorskip("pybullet")

from tests.perception.scenes import FRONT, frames, hand_scene


@pytest.fixture(scope="module")
def front():
    scene, _ = hand_scene()
    try:
        (frame,) = frames(scene, FRONT)
    finally:
        scene.close()
    return frame


def _truth_masks(frame, min_pixels=150):
    """Full-resolution masks of the labelled objects (not parts, not the table) with enough pixels."""
    out = {}
    for mask_id, label in frame.labels.items():
        if label.id is None or label.parent or label.category == "table":
            continue
        m = frame.masks == mask_id
        if m.sum() >= min_pixels:
            out[label.id] = m
    return out


def _iou(a, b):
    return float((a & b).sum()) / float((a | b).sum())


def test_geometry_finds_table_and_separates_loose_objects(front):
    dets = RGBDDetector(None).detect(front.rgb, front.depth, front.camera)
    assert isinstance(RGBDDetector(None), Detector)
    assert all(isinstance(d, Detection) and d.mask.shape == front.depth.shape for d in dets)
    assert dets[0].category == "table"
    table = next(k for k, lab in front.labels.items() if lab.id == "table")
    assert _iou(dets[0].mask, front.masks == table) > 0.8
    truth = _truth_masks(front)
    # objects standing free on the table: the cubes, the plate's cube, the stack's base
    for node in ("red_cube_1", "green_cube_1", "cyan_cube_1", "orange_cube_1"):
        best = max(_iou(d.mask, truth[node]) for d in dets[1:])
        assert best > 0.5, node
    assert all(d.attributes["category_source"] == "rule" for d in dets[1:])


def test_support_plane_is_the_table(front):
    seg, _ = segment(front.rgb, front.depth, front.camera)
    assert seg.plane is not None
    assert abs(seg.plane[2]) > 0.99 and abs(seg.plane[3]) < 0.005  # the table top is z = 0


def test_unmerged_over_segmentation_has_pairs(front):
    seg, (pairs, feats) = segment(front.rgb, front.depth, front.camera, merge=False)
    assert len(pairs) == len(feats) and feats.shape[1] == 11
    assert seg.count >= 6


@pytest.mark.parametrize(
    "bad",
    [
        lambda f: (f.rgb, None),
        lambda f: (f.rgb, f.depth[:-1]),
        lambda f: (f.rgb[:, :-1], f.depth),
        lambda f: (f.rgb, f.depth.astype(np.int32)),
        lambda f: (f.rgb[..., 0], f.depth),
    ],
)
def test_bad_input_is_one_clear_error(front, bad):
    rgb, depth = bad(front)
    with pytest.raises(GSRError, match="detect:"):
        RGBDDetector(None).detect(rgb, depth, front.camera)


def test_empty_and_nan_frames_give_no_objects(front):
    det = RGBDDetector(None)
    assert det.detect(front.rgb, np.zeros_like(front.depth), front.camera) == []
    assert det.detect(front.rgb, np.full_like(front.depth, np.nan), front.camera) == []
    noisy = front.depth.copy()
    noisy[::7, ::5] = np.nan  # holes are no return, not a crash
    assert len(det.detect(front.rgb, noisy, front.camera)) >= 5


def test_load_detector_rejects_a_folder_without_weights(tmp_path):
    with pytest.raises(GSRError, match="perceive-train"):
        load_detector(tmp_path)


def test_segment_params_are_used(front):
    coarse, _ = segment(front.rgb, front.depth, front.camera, SegmentParams(stride=4))
    assert coarse.labels.shape == (front.depth.shape[0] // 4, front.depth.shape[1] // 4)
