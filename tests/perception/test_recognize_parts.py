"""Closed drawers from their handles (gsr.perception.recognize_parts) on a hand-built point grid."""

from __future__ import annotations

import numpy as np
from gsr.perception.recognize_parts import Part, cut_dark_handles, drop_bare_handles, split_drawer_fronts
from gsr.perception.segment import Segments


def _grid(handle_x: float) -> tuple[Segments, np.ndarray, np.ndarray]:
    """A cabinet front (x = 0.5, facing -x, z 0.01..0.40) and two handles ``0.5 - handle_x`` in front."""
    h, w = 40, 36
    pts = np.full((h, w, 3), np.nan)
    nrm = np.full((h, w, 3), np.nan)
    rows, cols = np.mgrid[0:h, 0:30]
    pts[:, :30] = np.stack((np.full(rows.shape, 0.5), cols * 0.01, 0.4 - rows * 0.01), axis=-1)
    nrm[:, :30] = (-1.0, 0.0, 0.0)
    handle_low = np.zeros((h, w), bool)
    handle_high = np.zeros((h, w), bool)
    for mask, z in ((handle_low, 0.1), (handle_high, 0.25)):
        row = round((0.4 - z) / 0.01)
        r = slice(row - 2, row + 3)
        mask[r, 31:34] = True
        rr, cc = np.nonzero(mask)
        pts[rr, cc] = np.column_stack((np.full(rr.size, handle_x), 0.15 + (cc - 32) * 0.01, 0.4 - rr * 0.01))
        nrm[rr, cc] = (-1.0, 0.0, 0.0)
    labels = np.full((h, w), -1, np.int32)
    labels[:, :30] = 0
    labels[handle_low] = 1
    labels[handle_high] = 2
    seg = Segments(
        stride=1,
        shape=(h, w),
        labels=labels,
        support=np.zeros((h, w), bool),
        plane=np.array([0.0, 0.0, 1.0, 0.0]),
        points=pts,
        rgb=np.zeros((h, w, 3), np.uint8),
        normals=nrm,
        height=pts[..., 2],
        camera_position=np.array([-0.5, 0.15, 0.5]),
    )
    return seg, handle_low, handle_high


def _parts(seg: Segments) -> list[Part]:
    return [
        Part(seg.labels == 0, "cabinet", 0.9, None, 0),
        Part(seg.labels == 1, "drawer", 0.9, None, 1),
        Part(seg.labels == 2, "drawer", 0.9, None, 2),
    ]


def test_face_behind_handles_is_cut_into_one_band_per_drawer():
    seg, low, high = _grid(0.455)  # a pull bar 4.5 cm off the front
    parts = split_drawer_fronts(seg, _parts(seg))
    z = seg.points[..., 2]
    face = seg.labels == 0
    mid = (0.1 + 0.25) / 2
    assert parts[1].parent == 0 and parts[2].parent == 0
    assert np.array_equal(parts[1].mask & face, face & (z < mid))
    assert np.array_equal(parts[2].mask & face, face & (z >= mid))
    assert (parts[1].mask & low).sum() == low.sum()  # the handles stay with their drawers
    assert (parts[2].mask & high).sum() == high.sum()
    assert not (parts[0].mask & face).any()  # the whole front went to the drawers


def _one_segment(seg: Segments, handle_grey: int) -> list[Part]:
    """The cabinet's face and both handles as ONE cabinet segment (a grazing view: no depth jump, and a
    handle is rightly kept with its drawer's front); the face light grey, the handles ``handle_grey``."""
    whole = seg.labels >= 0
    seg.labels = np.where(whole, 0, -1).astype(np.int32)
    seg.rgb[whole] = 170
    seg.rgb[(seg.rgb.sum(axis=2) > 0) & (seg.points[..., 0] < 0.49)] = handle_grey
    return [Part(whole, "cabinet", 0.9, None, 0)]


def test_dark_pull_bars_left_in_the_cabinet_segment_become_drawers_with_their_bands():
    seg, low, high = _grid(0.455)
    parts = cut_dark_handles(seg, _one_segment(seg, handle_grey=40))
    assert [p.category for p in parts] == ["cabinet", "drawer", "drawer"]
    assert {int(p.mask.sum()) for p in parts[1:]} == {int(low.sum())}
    assert not (parts[0].mask & (low | high)).any()  # the bars left the cabinet
    parts = split_drawer_fronts(seg, parts)
    z, face = seg.points[..., 2], seg.points[..., 0] > 0.49
    assert all(p.parent == 0 for p in parts[1:])
    mid = (0.1 + 0.25) / 2
    low_drawer = next(p for p in parts[1:] if (p.mask & low).any())
    assert np.array_equal(low_drawer.mask & face, face & (z < mid))


def test_dark_marks_flush_with_the_face_or_only_a_little_darker_are_no_handles():
    seg, low, high = _grid(0.5)  # dark patches ON the face (a shadow, a print): no standoff
    parts = _one_segment(seg, handle_grey=170)
    seg.rgb[low | high] = 40
    assert [p.category for p in cut_dark_handles(seg, parts)] == ["cabinet"]
    seg, _, _ = _grid(0.455)  # standing off, but only shaded (not under 0.45 x the face's brightness)
    assert [p.category for p in cut_dark_handles(seg, _one_segment(seg, handle_grey=100))] == ["cabinet"]


def test_a_drawer_that_is_only_its_pull_bar_goes_back_to_its_cabinet():
    """A bar with no front band (its face edge-on or out of view) is no drawer node of its own; drawers
    with their bands stay."""
    seg, _, _ = _grid(0.455)
    banded = drop_bare_handles(seg, split_drawer_fronts(seg, _parts(seg)))
    assert [p.category for p in banded] == ["cabinet", "drawer", "drawer"]
    seg, _, _ = _grid(0.3)  # too far in front for a face band: the bars stay bare
    bare = drop_bare_handles(seg, split_drawer_fronts(seg, _parts(seg)))
    assert [p.category for p in bare] == ["cabinet"]
    assert np.array_equal(bare[0].mask, seg.labels >= 0)  # the bars' pixels are the cabinet's again


def test_a_handle_far_in_front_is_an_open_drawer_and_cuts_nothing():
    seg, _, _ = _grid(0.3)  # 20 cm in front: pulled out, not flush
    parts = split_drawer_fronts(seg, _parts(seg))
    assert np.array_equal(parts[0].mask, seg.labels == 0)
    assert np.array_equal(parts[1].mask, seg.labels == 1)
    assert parts[1].parent == 0  # still the nearest host within reach


def test_a_pulled_out_drawer_is_cut_out_of_the_cabinet_segment_that_swallowed_it():
    """Rendered: a cabinet with its low drawer pulled out 15 cm, given as ONE segment (what the segmenter
    makes of a drawer whose side is flush with the cabinet's). What stands out beyond the top's edge is
    the drawer; the rest stays the cabinet; a segment with nothing pulled out is left alone."""
    import pytest

    pytest.importorskip("pybullet")
    from gsr.perception.recognize_parts import split_open_drawers
    from gsr.perception.segment import segment

    from tests.perception.scenes import FRONT, frames, hand_scene

    scene, _ = hand_scene()
    try:
        (frame,) = frames(scene, FRONT)
    finally:
        scene.close()
    seg, _ = segment(frame.rgb, frame.depth, frame.camera)
    ids = {lab.id: k for k, lab in frame.labels.items() if lab.id}
    truth = frame.masks[:: seg.stride, :: seg.stride]
    cabinet, drawer = truth == ids["cabinet_1"], truth == ids["cabinet_1/drawer_low"]
    closed = truth == ids["cabinet_1/drawer_high"]
    whole = cabinet | drawer | closed
    parts = split_open_drawers(seg, [Part(whole.copy(), "drawer", 0.9, None, 0)])
    assert [p.category for p in parts] == ["cabinet", "drawer"]  # the whole was read as a drawer
    host, cut = parts
    assert cut.parent == 0
    iou = (cut.mask & drawer).sum() / (cut.mask | drawer).sum()
    assert iou > 0.5, iou
    assert (cut.mask & cabinet).sum() < 0.1 * cut.mask.sum()  # little of the body went with it
    assert not (host.mask & cut.mask).any() and (host.mask | cut.mask).sum() == whole.sum()
    alone = split_open_drawers(seg, [Part(cabinet.copy(), "cabinet", 0.9, None, 0)])
    assert len(alone) == 1 and np.array_equal(alone[0].mask, cabinet)


def test_a_pulled_out_drawer_of_its_own_segment_read_as_something_else_becomes_the_cabinets_drawer():
    """The drawer's box segmented on its own but recognised as, say, a caddy: hovering in front of the
    cabinet, within and across most of its width, it is the cabinet's drawer; objects on the table
    (resting on the support) keep their names."""
    import pytest

    pytest.importorskip("pybullet")
    from gsr.perception.recognize_parts import split_open_drawers
    from gsr.perception.segment import segment

    from tests.perception.scenes import FRONT, frames, hand_scene

    scene, _ = hand_scene()
    try:
        (frame,) = frames(scene, FRONT)
    finally:
        scene.close()
    seg, _ = segment(frame.rgb, frame.depth, frame.camera)
    ids = {lab.id: k for k, lab in frame.labels.items() if lab.id}
    truth = frame.masks[:: seg.stride, :: seg.stride]
    cabinet = (truth == ids["cabinet_1"]) | (truth == ids["cabinet_1/drawer_high"])
    parts = [
        Part(cabinet, "cabinet", 0.9, None, 0),
        Part(truth == ids["cabinet_1/drawer_low"], "caddy", 0.9, None, 1),
        Part(truth == ids["red_cube_1"], "cube", 0.9, None, 2),
        Part(truth == ids["green_cube_1"], "cube", 0.9, None, 3),
    ]
    out = split_open_drawers(seg, parts)
    assert [(p.category, p.parent) for p in out] == [
        ("cabinet", None),
        ("drawer", 0),
        ("cube", None),
        ("cube", None),
    ]
