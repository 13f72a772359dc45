"""Closed drawers that no camera shows are completed from a perceived drawer of the same stack."""

from __future__ import annotations

import numpy as np
from gsr.perception.camera import Camera
from gsr.perception.drawer_slots import hidden_drawers
from gsr.perception.frame import Frame, InstanceLabel
from gsr.perception.geometry import Instance, fit_boxes

W, H = 160, 120


def _box(key: str, label: InstanceLabel, lo: tuple, hi: tuple) -> Instance:
    grid = np.meshgrid(*(np.linspace(a, b, 8) for a, b in zip(lo, hi, strict=True)))
    points = np.column_stack([g.ravel() for g in grid])
    inst = Instance(key=key, label=label, points=points, rgb=np.full((len(points), 3), 120, np.uint8))
    fit_boxes(inst)
    return inst


def _stack(labelled: bool = False) -> list[Instance]:
    """A cabinet (front face at x = 0, 32 cm high) with its top drawer pulled out 22 cm."""
    cabinet = _box(
        "cabinet_1",
        InstanceLabel(id="cabinet_1" if labelled else None, category="cabinet"),
        (0.0, -0.18, 0.0),
        (0.3, 0.18, 0.32),
    )
    drawer = _box(
        "cabinet_1/drawer_1",
        InstanceLabel(category="drawer", parent="cabinet_1"),
        (-0.22, -0.17, 0.23),
        (0.0, 0.17, 0.31),
    )
    return [cabinet, drawer]


def _camera(position: tuple, forward: tuple) -> Camera:
    z = np.asarray(forward, float) / np.linalg.norm(forward)
    y = np.array([0.0, 0.0, -1.0])
    y = y - (y @ z) * z
    y /= np.linalg.norm(y)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([np.cross(y, z), y, z])
    pose[:3, 3] = position
    return Camera(W, H, 100.0, 100.0, W / 2, H / 2, pose)


def _frame(camera: Camera, face_x: float | None) -> Frame:
    """A frame whose depth is the plane x = ``face_x`` (the cabinet's front seen), or empty."""
    depth = np.zeros((H, W), np.float32)
    if face_x is not None:
        u, v = np.meshgrid(np.arange(W), np.arange(H))
        rays = np.stack(
            [(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u, float)], -1
        )
        along_x = rays @ camera.cam_to_world[0, :3]
        depth = ((face_x - camera.position[0]) / along_x).astype(np.float32)
    return Frame(
        rgb=np.zeros((H, W, 3), np.uint8), depth=depth, masks=np.full((H, W), -1, np.int32), camera=camera
    )


def test_levels_under_a_pulled_drawer_that_no_camera_sees_get_closed_drawers():
    behind = _frame(_camera((1.2, 0.0, 0.5), (-1.0, 0.0, -0.3)), None)  # sees the cabinet's back
    added = hidden_drawers(_stack(), [behind])
    assert len(added) == 2
    centres = sorted(float(d.center[2]) for d in added)
    assert 0.05 < centres[0] < 0.13  # the bottom level
    assert 0.14 < centres[1] < 0.22  # the middle level
    for d in added:
        assert d.label.parent == "cabinet_1" and d.label.category == "drawer"
        assert d.label.attributes["inferred"] is True and d.views == 0
        assert d.aabb_min[0] >= -1e-6 and d.aabb_max[0] <= 0.3  # closed: inside the carcass
    assert len({d.key for d in added} | {"cabinet_1/drawer_1"}) == 3


def test_a_front_that_a_camera_sees_without_a_drawer_is_not_completed():
    front = _frame(_camera((-1.0, 0.0, 0.5), (1.0, 0.0, -0.3)), 0.0)
    assert hidden_drawers(_stack(), [front]) == []
    # the same camera with nothing measured there leaves the levels unobserved
    assert len(hidden_drawers(_stack(), [_frame(front.camera, None)])) == 2


def test_labelled_masks_and_stacks_without_a_one_level_drawer_are_left_alone():
    behind = _frame(_camera((1.2, 0.0, 0.5), (-1.0, 0.0, -0.3)), None)
    assert hidden_drawers(_stack(labelled=True), [behind]) == []
    cabinet, drawer = _stack()
    tall = _box("cabinet_1/drawer_1", drawer.label, (-0.22, -0.17, 0.05), (0.0, 0.17, 0.31))
    assert hidden_drawers([cabinet, tall], [behind]) == []  # most of the cabinet's height: no level known
    narrow = _box("cabinet_1/drawer_1", drawer.label, (-0.22, -0.03, 0.23), (0.0, 0.03, 0.31))
    assert hidden_drawers([cabinet, narrow], [behind]) == []  # not a column across the width
