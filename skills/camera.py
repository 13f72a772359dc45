"""Cameras in the simulated world: RGB, metric depth and instance masks with intrinsics and extrinsics.

:func:`render_frame` returns a ``gsr.perception.Frame`` whose mask ids are one per scene-graph node (objects
and articulated parts, from PyBullet's object-and-link segmentation), with labels naming the node, its
category, colour and parent: ground truth for the perception pipeline. Rendering uses the CPU tiny
renderer (headless); camera poses use the world frame (+x forward from the robot, +y left, +z up).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from gsr.perception.camera import Camera, camera_from_gl, depth_from_gl_buffer, split_gl_segmentation
from gsr.perception.frame import Frame, InstanceLabel

if TYPE_CHECKING:
    from gsr.skills.world import World


@dataclass(frozen=True, slots=True)
class CameraSpec:
    """A pinhole camera looking from ``eye`` at ``target``; ``fov`` is the vertical field of view (deg)."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov: float = 60.0
    width: int = 320
    height: int = 240
    near: float = 0.05
    far: float = 4.0


def default_views(world: World) -> dict[str, CameraSpec]:
    """Named views of the table: ``front`` (over the robot's shoulder), ``top``, ``left``, ``right``."""
    lo, hi = world.body_aabb(world.table_body)
    cx, cy, cz = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]
    target = (cx, cy, cz + 0.05)
    return {
        # beside the robot, not behind it: the arm would hide the table
        "front": CameraSpec((lo[0] - 0.1, cy - 0.75, cz + 0.85), target),
        "top": CameraSpec((cx - 0.01, cy, cz + 1.4), (cx, cy, cz), up=(1.0, 0.0, 0.0)),
        "left": CameraSpec((cx, cy + 1.0, cz + 0.6), target),
        "right": CameraSpec((cx, cy - 1.0, cz + 0.6), target),
    }


@dataclass(frozen=True)
class RGBD:
    """One rendering: RGB (HxWx3 uint8), depth (HxW float32 m, 0 = nothing), body and link ids per pixel."""

    rgb: np.ndarray
    depth: np.ndarray
    body: np.ndarray
    link: np.ndarray
    camera: Camera


def capture_gl(
    client: int,
    eye: Sequence[float],
    target: Sequence[float],
    up: Sequence[float],
    fov: float,
    width: int,
    height: int,
    near: float,
    far: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """One TinyRenderer capture: RGB (uint8), metric depth, the raw segmentation buffer and the camera."""
    import pybullet as p

    view = p.computeViewMatrix(eye, target, up, physicsClientId=client)
    proj = p.computeProjectionMatrixFOV(fov, width / height, near, far, physicsClientId=client)
    _, _, rgba, depth_buf, seg = p.getCameraImage(
        width,
        height,
        view,
        proj,
        renderer=p.ER_TINY_RENDERER,
        flags=p.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
        physicsClientId=client,
    )
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
    depth = depth_from_gl_buffer(np.asarray(depth_buf).reshape(height, width), proj)
    return rgb, depth, np.asarray(seg).reshape(height, width), camera_from_gl(view, proj, width, height)


def render(world: World, spec: CameraSpec) -> RGBD:
    """Render RGB, depth and segmentation of the world from one camera."""
    rgb, depth, seg, camera = capture_gl(
        world.client, spec.eye, spec.target, spec.up, spec.fov, spec.width, spec.height, spec.near, spec.far
    )
    body, link = split_gl_segmentation(seg)
    return RGBD(rgb, depth, body, link, camera)


def node_of_pixels(world: World, body: np.ndarray, link: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """Per-pixel index into the returned node-id list (-1 = robot, background or unnamed)."""
    names: list[str] = []
    index: dict[str, int] = {}
    out = np.full(body.shape, -1, dtype=np.int32)
    for b, lk in {(int(b), int(lk)) for b, lk in zip(body.ravel(), link.ravel(), strict=True) if b >= 0}:
        node = _pixel_node(world, b, lk)
        if node is None:
            continue
        if node not in index:
            index[node] = len(names)
            names.append(node)
        out[(body == b) & (link == lk)] = index[node]
    return out, names


def _pixel_node(world: World, body: int, link: int) -> str | None:
    """A pixel's node: any part whose link it shows (the first by id), else its object when in the graph."""
    owner = world.link_owner(body, link)
    if owner is None:
        return None
    obj, parts = owner
    if parts:
        return min(parts)
    return obj if world.graph.has_node(obj) else None


def labelled_masks(world: World, img: RGBD) -> tuple[np.ndarray, dict[int, InstanceLabel]]:
    """One mask id per visible scene-graph node of a rendering, and each id's ``InstanceLabel``."""
    masks, names = node_of_pixels(world, img.body, img.link)
    labels = {}
    for i, nid in enumerate(names):
        n = world.graph.node(nid)
        labels[i] = InstanceLabel(id=nid, category=n.category, color=n.color, parent=n.parent)
    return masks, labels


def render_frame(world: World, spec: CameraSpec) -> Frame:
    """A ``gsr.perception.Frame``: RGB-D plus one mask id per visible scene-graph node, labelled with its node."""
    img = render(world, spec)
    masks, labels = labelled_masks(world, img)
    return Frame(rgb=img.rgb, depth=img.depth, masks=masks, camera=img.camera, labels=labels)


def save_png(rgb: np.ndarray, path: str) -> None:
    """Write an RGB image as PNG (atomically)."""
    import os
    import tempfile

    from PIL import Image

    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".png")
    os.close(fd)
    Image.fromarray(rgb).save(tmp, format="PNG")
    os.chmod(tmp, 0o644)  # mkstemp makes private files; images are meant to be shared
    os.replace(tmp, path)
