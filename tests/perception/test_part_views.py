"""Partial views of one drawer that fusion leaves apart become one part; stacked or side-by-side drawers do not."""

from __future__ import annotations

import numpy as np
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import GeometryParams, Instance, fit_boxes
from gsr.perception.track import assign_parts, fuse_views, same_part


def _inst(key: str, category: str, lo, hi, parent: str | None = None, seed: int = 0) -> Instance:
    rng = np.random.default_rng(seed)
    pts = rng.uniform(lo, hi, size=(400, 3))
    # a part detection names its view's cabinet (mask 0) as parent, as the detector's parent_index does
    attrs = {"parent_detection": 0} if category == "drawer" and parent is None else {}
    label = InstanceLabel(category=category, parent=parent, attributes=attrs)
    inst = Instance(key, label, pts, np.full((400, 3), 128, np.uint8))
    fit_boxes(inst)
    return inst


def _cabinet_views() -> list[Instance]:
    """A cabinet (front face at x = 0.3) with a low and a high drawer, seen by two cameras. Camera 0 splits
    the high drawer into its front and a slice of its side (two segments of one view); camera 1 sees it whole."""
    return [
        _inst("cabinet_f0m0", "cabinet", (0.0, 0.0, 0.0), (0.3, 0.4, 0.3), seed=1),
        _inst("cabinet_f1m0", "cabinet", (0.0, 0.0, 0.0), (0.3, 0.4, 0.3), seed=2),
        _inst("drawer_f0m1", "drawer", (0.28, 0.02, 0.02), (0.32, 0.38, 0.13), seed=3),  # low drawer
        _inst("drawer_f1m1", "drawer", (0.28, 0.02, 0.02), (0.32, 0.38, 0.13), seed=4),
        _inst(
            "drawer_f0m2", "drawer", (0.28, 0.02, 0.15), (0.45, 0.38, 0.28), seed=5
        ),  # high drawer, pulled out
        _inst(
            "drawer_f0m3", "drawer", (0.33, 0.02, 0.17), (0.43, 0.12, 0.24), seed=6
        ),  # camera 0's side slice
        _inst("drawer_f1m2", "drawer", (0.28, 0.02, 0.15), (0.45, 0.38, 0.28), seed=7),
    ]


def test_a_drawer_split_in_one_view_is_one_part_after_fusion():
    fused = fuse_views(_cabinet_views(), GeometryParams(voxel=0))
    assign_parts(fused, params=GeometryParams(voxel=0))
    drawers = sorted((i for i in fused if i.label.category == "drawer"), key=lambda i: i.aabb_min[2])
    assert len(drawers) == 2, [(d.key, d.aabb_min.round(2), d.aabb_max.round(2)) for d in drawers]
    low, high = drawers
    assert low.aabb_max[2] < 0.14 and high.aabb_min[2] > 0.14  # the stacked drawers stay apart
    assert high.views == 2 and high.label.parent == low.label.parent
    assert len({d.key for d in drawers}) == 2
    assert all(not k.startswith("_") for i in fused for k in i.label.attributes)


def test_stacked_and_side_by_side_drawers_are_different_parts():
    low = _inst("c/drawer_1", "drawer", (0.28, 0.02, 0.02), (0.32, 0.38, 0.13), parent="c")
    high = _inst("c/drawer_2", "drawer", (0.28, 0.02, 0.14), (0.32, 0.38, 0.26), parent="c")
    left = _inst("c/drawer_3", "drawer", (0.28, 0.40, 0.02), (0.32, 0.70, 0.13), parent="c")
    slice_ = _inst("c/drawer_4", "drawer", (0.29, 0.05, 0.16), (0.32, 0.20, 0.24), parent="c")
    other = _inst("d/drawer_1", "drawer", (0.28, 0.02, 0.14), (0.32, 0.38, 0.26), parent="d")
    assert not same_part(low, high)  # distinct height ranges
    assert not same_part(low, left)  # one height, side by side
    assert same_part(high, slice_)  # a partial view inside the drawer's box, at its height
    assert not same_part(low, slice_)
    assert not same_part(high, other)  # another cabinet's drawer


def test_a_part_spanning_two_stacked_drawers_joins_neither():
    from gsr.perception.track import merge_part_views

    middle = _inst("c/drawer_1", "drawer", (0.28, 0.02, 0.14), (0.32, 0.38, 0.22), parent="c", seed=1)
    high = _inst("c/drawer_2", "drawer", (0.28, 0.02, 0.23), (0.32, 0.38, 0.31), parent="c", seed=2)
    both = _inst("c/drawer_3", "drawer", (0.28, 0.02, 0.14), (0.32, 0.38, 0.31), parent="c", seed=3)
    both.views = 2  # seen so by two cameras: not dropped as a one-view spanning part
    instances = [middle, high, both]
    left = merge_part_views(instances, list(instances), GeometryParams(voxel=0))
    assert len(left) == 3 and len(instances) == 3  # one tall box would make both drawers one
    piece = _inst("c/drawer_4", "drawer", (0.29, 0.05, 0.24), (0.31, 0.20, 0.30), parent="c", seed=4)
    instances = [middle, high, piece]
    left = merge_part_views(instances, list(instances), GeometryParams(voxel=0))
    assert len(left) == 2 and {i.key for i in instances} == {"c/drawer_1", "c/drawer_2"}
    assert len(next(i for i in instances if i.key == "c/drawer_2").points) > 400
