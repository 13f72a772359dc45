"""Camera API: RGB, metric depth and node masks with intrinsics/extrinsics."""

from __future__ import annotations

import numpy as np
from gsr.perception.camera import split_gl_segmentation
from gsr.skills.camera import Light, default_views, no_masks, render, render_frame


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


def test_render_frame_options_change_only_what_they_name(bowl_world) -> None:
    # the one frame path: light, mask source and robot-free depth each change their own part of a frame
    views = default_views(bowl_world)
    spec = next(s for s in views.values() if (render(bowl_world, s).body == bowl_world.robot.body).any())
    img = render(bowl_world, spec)
    robot = img.body == bowl_world.robot.body
    plain = render_frame(bowl_world, spec)
    free = render_frame(bowl_world, spec, robot_free=True)
    assert np.all(free.depth[robot] == 0.0) and np.all(plain.depth[robot] > 0.0)
    assert np.array_equal(free.depth[~robot], plain.depth[~robot])
    assert np.array_equal(free.rgb, plain.rgb) and np.array_equal(free.masks, plain.masks)
    lit = render_frame(bowl_world, spec, light=Light((0.3, -0.5, 0.8), 0.8, 0.3))
    assert not np.array_equal(lit.rgb, plain.rgb)
    assert np.array_equal(lit.depth, plain.depth) and np.array_equal(lit.masks, plain.masks)
    assert lit.labels == plain.labels
    bare = render_frame(bowl_world, spec, masks=no_masks)
    assert np.all(bare.masks == -1) and bare.labels == {}
    raw = render_frame(bowl_world, spec, masks=lambda world, rendering: (rendering.segmentation, {}))
    body, link = split_gl_segmentation(raw.masks)
    assert np.array_equal(body, img.body) and np.array_equal(link, img.link)
