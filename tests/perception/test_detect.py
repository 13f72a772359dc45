"""No-oracle detection (gsr.perception.detect): instances from RGB + depth + camera, bad input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from gsr.perception.detect import Detection, Detector, RGBDDetector, load_detector
from gsr.perception.segment import PAIR_FEATURE_NAMES, SegmentParams, segment

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
    assert len(pairs) == len(feats) and feats.shape[1] == len(PAIR_FEATURE_NAMES)
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


def test_half_resolution_works_on_the_same_grid(front):
    """A 320x240 image of a view is segmented on the grid of its 640x480 image (stride 1 instead of 2), so
    the trained models see the same pixel counts and neighbour distances at either resolution."""
    from gsr.benchmarks.perception.render import render

    from tests.perception.scenes import FRONT

    scene, _ = hand_scene()
    try:
        small = render(scene, dataclasses.replace(FRONT, width=320, height=240))
    finally:
        scene.close()
    big_seg, _ = segment(front.rgb, front.depth, front.camera)
    small_seg, _ = segment(small.rgb, small.depth, small.camera)
    assert (big_seg.stride, small_seg.stride) == (2, 1)
    assert big_seg.labels.shape == small_seg.labels.shape == (240, 320)
    dets = RGBDDetector(None).detect(small.rgb, small.depth, small.camera)
    assert dets[0].mask.shape == (240, 320)
    truth = _truth_masks(small, min_pixels=40)
    for node in ("red_cube_1", "green_cube_1", "cyan_cube_1", "orange_cube_1"):
        assert max(_iou(d.mask, truth[node]) for d in dets[1:]) > 0.5, node
    # an explicit stride is kept
    assert segment(small.rgb, small.depth, small.camera, SegmentParams(stride=2))[0].stride == 2


def test_depth_noise_estimate_tells_clean_from_noisy_depth(front):
    """The link model reads the frame's depth noise: a 1 cm step is a boundary on clean depth only."""
    from gsr.perception.corrupt import add_depth_noise
    from gsr.perception.segment import depth_noise

    rng = np.random.default_rng(0)
    levels = []
    for sigma in (0.0, 0.002, 0.005):
        d = add_depth_noise(front.depth, sigma, rng) if sigma else front.depth
        z = d[::2, ::2].astype(np.float64)
        levels.append(depth_noise(z, z > 0))
    assert levels[0] < 2e-4 < levels[1] < levels[2]
    assert depth_noise(np.zeros((5, 5)), np.zeros((5, 5), bool)) == 0.0


def test_sealing_closes_short_gaps_in_a_boundary():
    """A boundary cut at every link but one still separates its two sides when sealed."""
    from gsr.perception.segment import sealed_components

    active = np.ones((20, 20), bool)
    kr = np.ones((20, 19), bool)
    kd = np.ones((19, 20), bool)
    kr[:, 9] = False  # a vertical boundary between columns 9 and 10 ...
    kr[12, 9] = True  # ... with one kept link across it
    leaky = sealed_components(active, kr, kd, seal=0)
    sealed = sealed_components(active, kr, kd, seal=1)
    assert leaky[0, 0] == leaky[0, 19]
    assert sealed[0, 0] != sealed[0, 19]
    assert len(np.unique(sealed[:, :9])) == 1 and len(np.unique(sealed[:, 11:])) == 1
    assert (sealed >= 0).all()


def _wall_grid() -> tuple[object, np.ndarray, np.ndarray, np.ndarray]:
    """A cabinet's face (x = 0, y 0..0.35, z 0.05..0.35) seen as one segment, a 4 x 6 cm strip of it
    below its seen part (z 0.01..0.05, behind a pulled-out drawer) as another, and a 4 cm cube 20 cm away."""
    from gsr.perception.segment import Segments

    h, w = 40, 50
    pts = np.full((h, w, 3), np.nan)
    rows, cols = np.mgrid[0:h, 0:w]
    pts[..., 0] = 0.0
    pts[..., 1] = cols * 0.01
    pts[..., 2] = 0.35 - rows * 0.01
    face = (cols < 36) & (rows <= 30)
    strip = (cols >= 10) & (cols < 14) & (rows > 30) & (rows <= 34)
    cube = (cols >= 44) & (cols < 48) & (rows >= 30) & (rows < 34)
    pts[cube] = np.column_stack((np.full(cube.sum(), 0.2), pts[cube][:, 1], pts[cube][:, 2]))
    pts[~(face | strip | cube)] = np.nan
    seg = Segments(
        stride=1,
        shape=(h, w),
        labels=np.full((h, w), -1, np.int32),
        support=np.zeros((h, w), bool),
        plane=np.array([0.0, 0.0, 1.0, 0.0]),
        points=pts,
        rgb=np.zeros((h, w, 3), np.uint8),
        normals=np.zeros((h, w, 3)),
        height=pts[..., 2],
        camera_position=np.array([-1.0, 0.2, 0.5]),
    )
    return seg, face, strip, cube


def test_a_tiny_piece_inside_a_larger_segment_of_its_category_joins_it():
    from gsr.perception.detect import absorb_fragments
    from gsr.perception.recognize_parts import Part

    seg, face, strip, cube = _wall_grid()
    reference = {"cabinet": 0.036, "cube": 2e-5}
    parts = [
        Part(face, "cabinet", 0.9, None, 0),
        Part(strip, "cabinet", 0.9, None, 1),
        Part(cube, "cube", 0.9, None, 2),
    ]
    out = absorb_fragments(seg, parts, reference)
    assert [p.category for p in out] == ["cabinet", "cube"]
    assert np.array_equal(out[0].mask, face | strip)
    # a piece of another category, or one that is no fragment by volume, stays
    parts = [Part(face, "cabinet", 0.9, None, 0), Part(strip, "box", 0.9, None, 1)]
    assert len(absorb_fragments(seg, parts, {**reference, "box": 0.003})) == 2
    parts = [Part(face, "cabinet", 0.9, None, 0), Part(strip, "cabinet", 0.9, None, 1)]
    assert len(absorb_fragments(seg, parts, {"cabinet": 1e-5})) == 2
