"""Pinhole camera model, its JSON format, and conversion from OpenGL (PyBullet) camera matrices.

Conventions: the camera frame is OpenCV's (x right, y down, z forward, metres); pixel ``(u, v)`` is
column ``u``, row ``v`` and its centre has integer coordinates. ``cam_to_world`` is the 4x4 pose of the
camera in the world frame (world: +x forward from the robot base, +y left, +z up).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gsr.errors import GSRError
from gsr.io import write_text_atomic

# OpenGL camera axes (x right, y up, z backward) -> OpenCV camera axes (x right, y down, z forward).
_GL_TO_CV = np.diag([1.0, -1.0, -1.0, 1.0])


@dataclass(frozen=True)
class Camera:
    """Intrinsics (pixels) and extrinsics (camera-to-world pose) of one pinhole camera."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    cam_to_world: np.ndarray  # 4x4, float64

    def __post_init__(self) -> None:
        pose = np.asarray(self.cam_to_world, dtype=np.float64)
        if pose.shape != (4, 4):
            raise GSRError(f"camera: cam_to_world must be 4x4, got shape {pose.shape}")
        object.__setattr__(self, "cam_to_world", pose)
        if self.width <= 0 or self.height <= 0:
            raise GSRError(f"camera: width and height must be positive, got {self.width}x{self.height}")
        if self.fx <= 0 or self.fy <= 0:
            raise GSRError(f"camera: fx and fy must be positive, got fx={self.fx} fy={self.fy}")
        if not np.allclose(pose[3], [0, 0, 0, 1]):
            raise GSRError("camera: cam_to_world's last row must be [0, 0, 0, 1]")
        rot = pose[:3, :3]
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-4):
            raise GSRError("camera: cam_to_world's rotation block is not orthonormal")

    @property
    def position(self) -> np.ndarray:
        """The camera centre in the world frame."""
        return self.cam_to_world[:3, 3].copy()

    def project(
        self, points: np.ndarray, near: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """World points ``(N, 3)`` seen by this camera: the nearest pixel's column ``u`` and row ``v`` (int),
        the depth ``z`` along the optical axis, and ``inside``: in front of the camera by more than ``near``
        and within the image. ``u`` and ``v`` are 0 where not ``inside`` (a NaN point is never inside)."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        rot, t = self.cam_to_world[:3, :3], self.cam_to_world[:3, 3]
        cam = (pts - t) @ rot  # rot.T @ (p - t) for every point: OpenCV camera frame, z forward
        z = cam[:, 2]
        front = z > near
        safe = np.where(front, z, 1.0)
        u = np.round(self.fx * cam[:, 0] / safe + self.cx)
        v = np.round(self.fy * cam[:, 1] / safe + self.cy)
        inside = front & (u >= 0) & (u < self.width) & (v >= 0) & (v < self.height)
        return np.where(inside, u, 0).astype(int), np.where(inside, v, 0).astype(int), z, inside

    def rays(self, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Normalised image coordinates ``(x/z, y/z)`` of every pixel on the strided grid, each (H', W'):
        the inverse of :meth:`project` up to the depth (back-projection multiplies them by the depth)."""
        u = (np.arange(0, self.width, stride, dtype=np.float64) - self.cx) / self.fx
        v = (np.arange(0, self.height, stride, dtype=np.float64) - self.cy) / self.fy
        return np.broadcast_to(u[None, :], (v.size, u.size)), np.broadcast_to(v[:, None], (v.size, u.size))

    def to_dict(self) -> dict[str, Any]:
        """The camera JSON object (see docs/perception.md)."""
        return {
            "width": self.width,
            "height": self.height,
            "fx": self.fx,
            "fy": self.fy,
            "cx": self.cx,
            "cy": self.cy,
            "cam_to_world": self.cam_to_world.tolist(),
        }


def camera_from_dict(data: Any, source: str = "<camera>") -> Camera:
    """Validate a decoded camera JSON object; errors name the source and the field."""
    if not isinstance(data, dict):
        raise GSRError(f"{source}: camera must be a JSON object")
    values: dict[str, Any] = {}
    for key in ("width", "height"):
        v = data.get(key)
        if not isinstance(v, int) or isinstance(v, bool):
            raise GSRError(f"{source}: field {key!r} must be an integer, got {v!r}")
        values[key] = v
    for key in ("fx", "fy", "cx", "cy"):
        v = data.get(key)
        if not isinstance(v, int | float) or isinstance(v, bool) or not math.isfinite(v):
            raise GSRError(f"{source}: field {key!r} must be a finite number, got {v!r}")
        values[key] = float(v)
    pose = data.get("cam_to_world")
    try:
        arr = np.asarray(pose, dtype=np.float64)
    except (TypeError, ValueError):
        raise GSRError(f"{source}: field 'cam_to_world' must be a 4x4 array of numbers") from None
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise GSRError(f"{source}: field 'cam_to_world' must be a 4x4 array of finite numbers")
    unknown = set(data) - {"width", "height", "fx", "fy", "cx", "cy", "cam_to_world"}
    if unknown:
        raise GSRError(f"{source}: unknown camera field(s) {', '.join(sorted(unknown))}")
    try:
        return Camera(cam_to_world=arr, **values)
    except GSRError as exc:
        raise GSRError(f"{source}: {exc}") from None


def load_camera(path: str | Path) -> Camera:
    """Read a camera JSON file."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise GSRError(f"{p}: no such file") from None
    except OSError as exc:
        raise GSRError(f"{p}: cannot read: {exc.strerror}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise GSRError(f"{p}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
    return camera_from_dict(data, str(p))


def save_camera(camera: Camera, path: str | Path) -> None:
    """Write a camera JSON file atomically."""
    write_text_atomic(Path(path), json.dumps(camera.to_dict(), indent=2) + "\n")


# ------------------------------------------------------------------ OpenGL / PyBullet conversion


def _gl_matrix(values: Any, name: str) -> np.ndarray:
    """A 4x4 matrix from 16 numbers in OpenGL's column-major order (as PyBullet returns them)."""
    arr = np.asarray(values, dtype=np.float64).reshape(-1)
    if arr.size != 16:
        raise GSRError(f"{name} must hold 16 numbers, got {arr.size}")
    return arr.reshape(4, 4).T  # column-major list -> row-major matrix


def near_far_from_projection(projection: Any) -> tuple[float, float]:
    """The near and far clipping distances of an OpenGL perspective projection matrix."""
    p = _gl_matrix(projection, "projection matrix")
    a, b = p[2, 2], p[2, 3]  # a = -(f+n)/(f-n), b = -2fn/(f-n)
    if p[3, 2] != -1.0 or abs(a - 1.0) < 1e-12 or abs(a + 1.0) < 1e-12:
        raise GSRError("projection matrix is not an OpenGL perspective projection")
    return float(b / (a - 1.0)), float(b / (a + 1.0))


def camera_from_gl(view: Any, projection: Any, width: int, height: int, renderer: str = "tiny") -> Camera:
    """A ``Camera`` from PyBullet's view and projection matrices (16 numbers each, column-major).

    ``renderer`` fixes the sub-pixel convention: ``"tiny"`` (PyBullet's TinyRenderer, the one DIRECT
    mode has) samples pixel ``u`` at window x = u and stores rows bottom-up from y = height - 1;
    ``"opengl"`` (hardware OpenGL/EGL) samples pixel centres, x = u + 0.5.
    """
    if renderer not in ("tiny", "opengl"):
        raise GSRError(f"renderer must be 'tiny' or 'opengl', got {renderer!r}")
    v = _gl_matrix(view, "view matrix")
    p = _gl_matrix(projection, "projection matrix")
    near_far_from_projection(projection)  # validates the projection's form
    # The view matrix maps world to the GL camera frame; invert it and flip y/z to OpenCV axes.
    cam_to_world = np.linalg.inv(v) @ _GL_TO_CV
    cam_to_world[3] = (0.0, 0.0, 0.0, 1.0)
    # x_ndc = P00 * X/Z - P02, window x = (x_ndc + 1) * width / 2; rows run top-down in the image.
    fx = p[0, 0] * width / 2.0
    fy = p[1, 1] * height / 2.0
    shift_x, shift_y = (0.0, 1.0) if renderer == "tiny" else (0.5, 0.5)
    cx = width / 2.0 * (1.0 - p[0, 2]) - shift_x
    cy = height / 2.0 * (1.0 + p[1, 2]) - shift_y
    return Camera(int(width), int(height), float(fx), float(fy), float(cx), float(cy), cam_to_world)


def depth_from_gl_buffer(buffer: Any, projection: Any) -> np.ndarray:
    """Metric depth (distance along the optical axis, metres; 0 = no return) from a GL depth buffer."""
    near, far = near_far_from_projection(projection)
    d = np.asarray(buffer, dtype=np.float64)
    depth = far * near / (far - (far - near) * d)
    # The far plane means "nothing was hit" (background), not a surface at `far` metres.
    depth[(d >= 1.0 - 1e-7) | ~np.isfinite(depth)] = 0.0
    return depth.astype(np.float32)


def split_gl_segmentation(seg: Any) -> tuple[np.ndarray, np.ndarray]:
    """Body ids and link indices from PyBullet's OBJECT_AND_LINKINDEX segmentation (-1 = none)."""
    s = np.asarray(seg, dtype=np.int64)
    background = s < 0
    body = np.where(background, -1, s & ((1 << 24) - 1))
    link = np.where(background, -2, (s >> 24) - 1)  # link -1 is the base
    return body.astype(np.int32), link.astype(np.int32)
