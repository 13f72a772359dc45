"""Cameras in the simulated world: RGB, metric depth and instance masks with intrinsics and extrinsics.

:func:`render_frame` is the one place a rendering becomes a ``gsr.perception.Frame``: by default its mask
ids are one per scene-graph node (objects and articulated parts, from PyBullet's object-and-link
segmentation), with labels naming the node, its category, colour and parent: ground truth for the
perception pipeline. Its options: a :class:`Light` (randomised training light), where the masks come
from (a :data:`MaskSource`: the world's nodes, a scene's own segmentation labels, doors added, or none
for a detector's input) and ``robot_free`` (no depth on the robot's own pixels). Rendering uses the CPU
tiny renderer (headless); camera poses use the world frame (+x forward from the robot, +y left, +z up).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

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

    @property
    def segmentation(self) -> np.ndarray:
        """PyBullet's object-and-link segmentation values, ``body + (link + 1) << 24`` (-1 = nothing)."""
        return np.where(self.body < 0, -1, self.body + ((self.link + 1) << 24)).astype(np.int32)


@dataclass(frozen=True, slots=True)
class Light:
    """The tiny renderer's light: ``direction`` towards the light (world frame), ambient and diffuse
    coefficients. ``None`` wherever a light is asked for means PyBullet's default light."""

    direction: tuple[float, float, float]
    ambient: float
    diffuse: float


class Client(Protocol):
    """Anything rendered: a PyBullet client id (a ``World``, an offline perception ``Scene``)."""

    @property
    def client(self) -> int: ...


#: Where a frame's masks come from: ``(source, rendering) -> (mask ids per pixel, label per mask id)``.
MaskSource = Callable[[Any, "RGBD"], tuple[np.ndarray, dict[int, InstanceLabel]]]


def render(world: Client, spec: CameraSpec, light: Light | None = None) -> RGBD:
    """Render RGB, metric depth, body and link ids of a world (any PyBullet client) from one camera."""
    import pybullet as p

    client = world.client

    view = p.computeViewMatrix(spec.eye, spec.target, spec.up, physicsClientId=client)
    proj = p.computeProjectionMatrixFOV(
        spec.fov, spec.width / spec.height, spec.near, spec.far, physicsClientId=client
    )
    lit: dict[str, Any] = {}
    if light is not None:
        lit = {
            "lightDirection": list(light.direction),
            "lightAmbientCoeff": light.ambient,
            "lightDiffuseCoeff": light.diffuse,
        }
    w, h = spec.width, spec.height
    _, _, rgba, depth_buf, seg = p.getCameraImage(
        w,
        h,
        view,
        proj,
        **lit,
        renderer=p.ER_TINY_RENDERER,
        flags=p.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
        physicsClientId=client,
    )
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)[:, :, :3].copy()
    depth = depth_from_gl_buffer(np.asarray(depth_buf).reshape(h, w), proj)
    body, link = split_gl_segmentation(np.asarray(seg).reshape(h, w))
    return RGBD(rgb, depth, body, link, camera_from_gl(view, proj, w, h))


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


def no_masks(source: Any, img: RGBD) -> tuple[np.ndarray, dict[int, InstanceLabel]]:
    """No instance masks (every pixel -1, no labels): RGB-D only, what a detector gets to see."""
    return np.full(img.depth.shape, -1, dtype=np.int32), {}


def robot_free_depth(world: World, img: RGBD) -> np.ndarray:
    """The rendering's depth with no return on the robot's own pixels, as a robot filters itself out of
    its sensor data with its own model at its joint state (nothing else of the segmentation is used)."""
    return np.where(img.body == world.robot.body, 0.0, img.depth).astype(np.float32)


def render_frame(
    world: Client,
    spec: CameraSpec,
    *,
    light: Light | None = None,
    masks: MaskSource = labelled_masks,
    robot_free: bool = False,
) -> Frame:
    """A ``gsr.perception.Frame`` of one camera: every frame made from a rendering is made here.

    ``masks`` says where the instance masks and their labels come from: by default one id per visible
    scene-graph node of a ``World``, labelled with its node (:func:`labelled_masks`); :func:`no_masks` for
    RGB-D alone; or any other :data:`MaskSource` (the offline perception scenes' segmentation labels, the
    runtime loop's door masks). ``light`` replaces PyBullet's default light; ``robot_free`` leaves no depth
    on the robot's pixels (:func:`robot_free_depth`; the world must have a robot).
    """
    img = render(world, spec, light)
    ids, labels = masks(world, img)
    depth = robot_free_depth(world, img) if robot_free else img.depth  # type: ignore[arg-type]
    return Frame(rgb=img.rgb, depth=depth, masks=ids, camera=img.camera, labels=labels)


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
