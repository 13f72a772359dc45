"""Camera model, GL conversion and back-projection against known geometry."""

from __future__ import annotations

import json

import numpy as np
import pytest
from gsr.perception.camera import (
    Camera,
    camera_from_dict,
    camera_from_gl,
    depth_from_gl_buffer,
    load_camera,
    near_far_from_projection,
    save_camera,
    split_gl_segmentation,
)
from gsr.perception.geometry import back_project

from gsr.errors import GSRError

# Camera 1.5 m above the origin looking straight down; image "up" is world +x.
DOWN = np.array([[0.0, -1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 1.5], [0, 0, 0, 1.0]])


def test_back_projection_of_a_plane_below_a_downward_camera():
    cam = Camera(64, 48, 50.0, 50.0, 31.5, 23.5, DOWN)
    pts = back_project(np.full((48, 64), 1.5, np.float32), cam)
    assert pts.shape == (48, 64, 3)
    assert np.allclose(pts[..., 2], 0.0, atol=1e-9)  # every ray hits the table plane z = 0
    # pixel (u, v) = (cx + 10, cy) lies 10 px right of centre: x_cam = 10/50 * 1.5 = 0.3 -> world -y
    centre = (pts[23, 31] + pts[24, 32]) / 2.0
    assert np.allclose(centre, [0.0, 0.0, 0.0], atol=1e-9)
    assert np.allclose(pts[23, 41] - pts[23, 31], [0.0, -0.3, 0.0], atol=1e-9)
    assert np.allclose(pts[33, 31] - pts[23, 31], [-0.3, 0.0, 0.0], atol=1e-9)


def test_pixels_without_depth_back_project_to_nan():
    cam = Camera(4, 3, 2.0, 2.0, 1.5, 1.0, np.eye(4))
    depth = np.ones((3, 4), np.float32)
    depth[0, 0], depth[1, 1] = 0.0, np.nan
    pts = back_project(depth, cam)
    assert np.isnan(pts[0, 0]).all() and np.isnan(pts[1, 1]).all() and np.isfinite(pts[2, 2]).all()


def test_project_inverts_back_projection_pixel_for_pixel():
    cam = Camera(64, 48, 50.0, 50.0, 31.5, 23.5, DOWN)
    depth = np.random.default_rng(0).uniform(0.5, 1.5, (48, 64)).astype(np.float32)
    pts = back_project(depth, cam).reshape(-1, 3)
    u, v, z, inside = cam.project(pts)
    rows, cols = np.divmod(np.arange(48 * 64), 64)
    assert inside.all() and np.array_equal(u, cols) and np.array_equal(v, rows)
    assert np.allclose(z, depth.reshape(-1), atol=1e-6)


def test_project_marks_points_behind_outside_or_nan_as_not_inside():
    cam = Camera(64, 48, 50.0, 50.0, 31.5, 23.5, DOWN)
    pts = np.array(
        [[0.0, 0.0, 2.0], [0.0, 0.0, 1.4995], [5.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [0.0, 0.0, 0.0]]
    )
    u, v, z, inside = cam.project(pts, near=1e-3)
    # above the camera (behind it), 0.5 mm in front (nearer than `near`), far off the image, NaN, in view
    assert inside.tolist() == [False, False, False, False, True]
    assert (u[:4] == 0).all() and (v[:4] == 0).all() and z[0] < 0 and z[4] == pytest.approx(1.5)
    assert cam.project(pts[1:2])[3].tolist() == [True]  # near=0: any point in front counts


def test_camera_json_round_trip(tmp_path):
    cam = Camera(640, 480, 554.3, 554.3, 319.5, 239.5, DOWN)
    path = tmp_path / "cam.json"
    save_camera(cam, path)
    back = load_camera(path)
    assert back.width == 640 and back.fx == pytest.approx(554.3)
    assert np.allclose(back.cam_to_world, DOWN)


@pytest.mark.parametrize(
    ("patch", "message"),
    [
        ({"fx": "a"}, "field 'fx'"),
        ({"width": 1.5}, "field 'width'"),
        ({"cam_to_world": [[1, 0], [0, 1]]}, "cam_to_world"),
        ({"fy": -3.0}, "fx and fy must be positive"),
        ({"extra": 1}, "unknown camera field"),
        ({"cam_to_world": np.diag([2.0, 1.0, 1.0, 1.0]).tolist()}, "orthonormal"),
    ],
)
def test_bad_camera_fields_are_named(patch, message):
    data = Camera(640, 480, 500.0, 500.0, 320.0, 240.0, np.eye(4)).to_dict() | patch
    with pytest.raises(GSRError, match=message):
        camera_from_dict(data, "cam.json")


def test_load_camera_reports_file_and_position(tmp_path):
    bad = tmp_path / "cam.json"
    bad.write_text('{"width": 3,,}')
    with pytest.raises(GSRError, match=r"cam.json:1:\d+: invalid JSON"):
        load_camera(bad)
    with pytest.raises(GSRError, match="no such file"):
        load_camera(tmp_path / "missing.json")


def test_gl_projection_near_far_and_depth_linearisation():
    pb = pytest.importorskip("pybullet")
    proj = pb.computeProjectionMatrixFOV(60.0, 4 / 3, 0.1, 4.0)
    near, far = near_far_from_projection(proj)
    assert near == pytest.approx(0.1) and far == pytest.approx(4.0)
    # the GL depth buffer value of a point at distance z: d = (1/n - 1/z) / (1/n - 1/f)
    z = np.array([[0.1, 0.5, 2.0, 3.9]])
    d = (1 / near - 1 / z) / (1 / near - 1 / far)
    assert np.allclose(depth_from_gl_buffer(d, proj), z, rtol=1e-5)
    assert depth_from_gl_buffer(np.ones((1, 1)), proj)[0, 0] == 0.0  # far plane = no return
    with pytest.raises(GSRError, match="16 numbers"):
        near_far_from_projection([1.0] * 9)


def test_rendered_box_back_projects_onto_its_faces():
    """Render a box of known pose with PyBullet: its segment's points must lie on the box surface."""
    pb = pytest.importorskip("pybullet")
    cid = pb.connect(pb.DIRECT)
    try:
        half = np.array([0.05, 0.08, 0.04])
        centre = np.array([0.6, 0.1, 0.04])
        vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half.tolist(), physicsClientId=cid)
        body = pb.createMultiBody(baseVisualShapeIndex=vis, basePosition=centre.tolist(), physicsClientId=cid)
        w, h = 320, 240
        view = pb.computeViewMatrix([0.1, -0.2, 0.6], [0.6, 0.1, 0.0], [0, 0, 1], physicsClientId=cid)
        proj = pb.computeProjectionMatrixFOV(55.0, w / h, 0.05, 3.0, physicsClientId=cid)
        _, _, _, depth_buf, seg = pb.getCameraImage(
            w,
            h,
            view,
            proj,
            renderer=pb.ER_TINY_RENDERER,
            physicsClientId=cid,
            flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
        )
    finally:
        pb.disconnect(cid)
    cam = camera_from_gl(view, proj, w, h)
    assert np.allclose(cam.position, [0.1, -0.2, 0.6], atol=1e-6)
    depth = depth_from_gl_buffer(np.reshape(depth_buf, (h, w)), proj)
    bodies, links = split_gl_segmentation(np.reshape(seg, (h, w)))
    mask = (bodies == body) & (links == -1)
    assert mask.sum() > 500
    pts = back_project(depth, cam)[mask]
    local = np.abs(pts - centre)
    # every point lies on the box surface (0.1 mm): one coordinate sits at a face, none beyond it
    assert np.all(local <= half + 1e-4)
    assert np.all(np.min(np.abs(local - half), axis=1) < 1e-4)


def test_split_segmentation_decodes_body_and_link():
    seg = np.array([[-1, 3, 3 + (1 << 24), 7 + (4 << 24)]])
    bodies, links = split_gl_segmentation(seg)
    assert bodies.tolist() == [[-1, 3, 3, 7]]
    assert links.tolist() == [[-2, -1, 0, 3]]


def test_camera_file_format_is_plain_json(tmp_path):
    path = tmp_path / "c.json"
    save_camera(Camera(2, 2, 1.0, 1.0, 0.5, 0.5, np.eye(4)), path)
    assert set(json.loads(path.read_text())) == {"width", "height", "fx", "fy", "cx", "cy", "cam_to_world"}
