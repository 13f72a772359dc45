"""Camera API: RGB, metric depth and node masks with intrinsics/extrinsics."""

from __future__ import annotations

import numpy as np
from gsr.skills.camera import default_views, render, render_frame


def test_render_frame_labels_nodes(bowl_world) -> None:
    spec = default_views(bowl_world)["top"]
    frame = render_frame(bowl_world, spec)
    assert frame.rgb.shape == (spec.height, spec.width, 3) and frame.rgb.dtype == np.uint8
    ids = {label.id for label in frame.labels.values()}
    assert {"akita_black_bowl_1", "plate_1", "main_table"} <= ids
    bowl = next(i for i, label in frame.labels.items() if label.id == "akita_black_bowl_1")
    mask = frame.masks == bowl
    assert mask.sum() > 20
    depth = frame.depth[mask]
    assert np.all(depth > 0.5) and np.all(depth < 2.0)  # the top camera is 1.4 m above the table


def test_intrinsics_and_depth_agree_on_a_known_point(bowl_world) -> None:
    spec = default_views(bowl_world)["top"]
    img = render(bowl_world, spec)
    cam = img.camera
    # a point on the table top near a far corner (nothing stands there): project it with the intrinsics
    _lo, hi = bowl_world.body_aabb(bowl_world.table_body)
    p_world = np.array([hi[0] - 0.06, hi[1] - 0.06, hi[2], 1.0])
    p_cam = np.linalg.inv(cam.cam_to_world) @ p_world
    u = cam.fx * p_cam[0] / p_cam[2] + cam.cx
    v = cam.fy * p_cam[1] / p_cam[2] + cam.cy
    row, col = round(v), round(u)
    assert img.body[row, col] == bowl_world.table_body
    assert abs(float(img.depth[row, col]) - p_cam[2]) < 0.01
