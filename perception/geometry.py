"""Point geometry: back-projection, per-instance clouds, outlier removal, boxes, colour, support plane.

Everything is vectorised numpy; open3d does voxel down-sampling, statistical outlier removal and the
RANSAC plane fit. Objects are assumed to stand upright (gravity along world -z), so the oriented box
of an instance is the minimum-area rectangle of its footprint (yaw only) times its height range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from gsr.perception.camera import Camera
from gsr.perception.frame import Frame, InstanceLabel

from gsr.categories import COLORS


@dataclass(frozen=True)
class GeometryParams:
    """Tunable constants of the geometric front end (see docs/perception.md)."""

    stride: int = 2  # use every n-th pixel in each direction (640x480 -> 320x240)
    voxel: float = 0.004  # smallest voxel for down-sampling instance clouds (m)
    voxels_across: int = 64  # large instances (the table) get coarser voxels: extent / this
    outlier_neighbors: int = 12  # statistical outlier removal: neighbours considered
    outlier_std: float = 2.5  # ... and the std-dev ratio beyond which a point is dropped
    min_points: int = 8  # instances with fewer points (after filtering) are dropped
    small_instance: int = 40  # instances with fewer strided pixels are re-read at full resolution
    plane_distance: float = 0.006  # RANSAC inlier distance for the support plane (m)
    max_depth: float = 10.0  # returns beyond this are ignored (m)


@dataclass
class Instance:
    """One perceived object or part: its world-frame points and what was derived from them."""

    key: str
    label: InstanceLabel
    points: np.ndarray  # (N, 3) world frame
    rgb: np.ndarray  # (N, 3) uint8 colours of the points
    views: int = 1
    center: np.ndarray = field(default_factory=lambda: np.zeros(3))  # upright box centre
    size: np.ndarray = field(default_factory=lambda: np.zeros(3))  # extent along box x, y and z
    yaw: float = 0.0  # rotation of the box about world z (rad)
    aabb_min: np.ndarray = field(default_factory=lambda: np.zeros(3))
    aabb_max: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def axes(self) -> np.ndarray:
        """The box's horizontal unit axes as rows (box x, box y) in world xy."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, s], [-s, c]])

    def footprint_contains(self, xy: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Which world xy points fall inside the box footprint grown by ``margin``."""
        local = (xy - self.center[:2]) @ self.axes.T
        half = self.size[:2] / 2.0 + margin
        return np.all(np.abs(local) <= half, axis=1)


def box_contains_share(inner: Instance, outer: Instance, margin: float = 0.0) -> float:
    """Share of ``inner``'s axis-aligned box volume inside ``outer``'s, grown by ``margin`` (m) on every
    side (a degenerate inner box counts as at least 1 mm per side)."""
    lo = np.maximum(inner.aabb_min, outer.aabb_min - margin)
    hi = np.minimum(inner.aabb_max, outer.aabb_max + margin)
    inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
    return inter / float(np.prod(np.maximum(inner.aabb_max - inner.aabb_min, 1e-3)))


def pixel_rays(camera: Camera, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel normalised image coordinates ``(x/z, y/z)`` on the strided grid (:meth:`Camera.rays`)."""
    return camera.rays(stride)


def back_project(depth: np.ndarray, camera: Camera, stride: int = 1) -> np.ndarray:
    """World points (H', W', 3) of every (strided) pixel; pixels without depth give NaN."""
    z = np.asarray(depth, dtype=np.float64)[::stride, ::stride]
    rx, ry = pixel_rays(camera, stride)
    z = np.where(np.isfinite(z) & (z > 0), z, np.nan)
    cam = np.stack((rx * z, ry * z, z), axis=-1)
    rot, t = camera.cam_to_world[:3, :3], camera.cam_to_world[:3, 3]
    return cam @ rot.T + t


def instance_clouds(frame: Frame, params: GeometryParams) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Raw world points and colours of every mask id in a frame (one sort, no per-pixel loop).

    Pixels are read on the strided grid; instances that get fewer than ``small_instance`` pixels there
    (small or mostly hidden objects) are read again at full resolution so they are not lost.
    """
    out = _clouds(frame, params, params.stride, None)
    small = [i for i, (pts, _) in out.items() if len(pts) < params.small_instance]
    if small and params.stride > 1:
        out.update(_clouds(frame, params, 1, np.asarray(small)))
    return out


def _clouds(
    frame: Frame, params: GeometryParams, s: int, only: np.ndarray | None
) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    depth = np.asarray(frame.depth, dtype=np.float64)[::s, ::s]
    masks = frame.masks[::s, ::s]
    valid = (masks >= 0) & np.isfinite(depth) & (depth > 0) & (depth < params.max_depth)
    if only is not None:
        valid &= np.isin(masks, only)
    rx, ry = pixel_rays(frame.camera, s)
    z = depth[valid]
    cam = np.stack((rx[valid] * z, ry[valid] * z, z), axis=-1)
    rot, t = frame.camera.cam_to_world[:3, :3], frame.camera.cam_to_world[:3, 3]
    world = cam @ rot.T + t
    ids = masks[valid]
    if ids.size == 0:
        return {}  # nothing segmented has a depth return (an empty scene, a blank depth image)
    rgb = frame.rgb[::s, ::s][valid]
    order = np.argsort(ids, kind="stable")
    ids, world, rgb = ids[order], world[order], rgb[order]
    uniq, starts = np.unique(ids, return_index=True)
    ends = np.append(starts[1:], ids.size)
    return {int(i): (world[a:b], rgb[a:b]) for i, a, b in zip(uniq, starts, ends, strict=True)}


def clean_points(
    points: np.ndarray, rgb: np.ndarray, params: GeometryParams
) -> tuple[np.ndarray, np.ndarray]:
    """Voxel down-sample and drop statistical outliers (open3d); colours follow their points."""
    import open3d as o3d

    if len(points) < params.min_points:
        return points, rgb
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    pcd.colors = o3d.utility.Vector3dVector(rgb.astype(np.float64) / 255.0)
    if params.voxel > 0:
        # Keep a bounded number of voxels per instance: a 1 m table does not need 4 mm resolution.
        extent = float(np.max(points.max(axis=0) - points.min(axis=0)))
        pcd = pcd.voxel_down_sample(max(params.voxel, extent / params.voxels_across))
    if len(pcd.points) > params.outlier_neighbors * 2:
        pcd, _ = pcd.remove_statistical_outlier(params.outlier_neighbors, params.outlier_std)
    pts = np.asarray(pcd.points)
    cols = (np.asarray(pcd.colors) * 255.0).round().astype(np.uint8)
    return pts, cols


# Candidate yaw angles for the minimum-area footprint rectangle: 2-degree grid over a quarter turn.
_YAWS = np.deg2rad(np.arange(0.0, 90.0, 2.0))
_COS, _SIN = np.cos(_YAWS), np.sin(_YAWS)


def fit_boxes(inst: Instance) -> None:
    """Fill the instance's AABB and upright oriented box (min-area footprint rectangle)."""
    pts = inst.points
    inst.aabb_min, inst.aabb_max = pts.min(axis=0), pts.max(axis=0)
    x, y = pts[:, 0], pts[:, 1]
    # Project the footprint on every candidate axis pair at once: (angles, points).
    px = np.outer(_COS, x) + np.outer(_SIN, y)
    py = np.outer(-_SIN, x) + np.outer(_COS, y)
    lo_x, hi_x, lo_y, hi_y = px.min(1), px.max(1), py.min(1), py.max(1)
    k = int(np.argmin((hi_x - lo_x) * (hi_y - lo_y)))
    c, s = _COS[k], _SIN[k]
    mid_x, mid_y = (lo_x[k] + hi_x[k]) / 2.0, (lo_y[k] + hi_y[k]) / 2.0
    inst.yaw = float(_YAWS[k])
    inst.center = np.array(
        [c * mid_x - s * mid_y, s * mid_x + c * mid_y, (inst.aabb_min[2] + inst.aabb_max[2]) / 2.0]
    )
    inst.size = np.array([hi_x[k] - lo_x[k], hi_y[k] - lo_y[k], inst.aabb_max[2] - inst.aabb_min[2]])


def number_anonymous(instances: list[Instance]) -> None:
    """Give instances without a node id stable, readable keys: cube_1, cube_2, ... in order."""
    counts: dict[str, int] = {}
    for inst in instances:
        if inst.label.id is None:
            counts[inst.label.category] = counts.get(inst.label.category, 0) + 1
            inst.key = f"{inst.label.category}_{counts[inst.label.category]}"


def support_plane(points: np.ndarray, params: GeometryParams, seed: int = 0) -> np.ndarray | None:
    """RANSAC plane ``(a, b, c, d)`` with ``a x + b y + c z + d = 0`` and normal pointing up (+z)."""
    import open3d as o3d

    if len(points) < 3:
        return None
    o3d.utility.random.seed(seed)
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    plane, inliers = pcd.segment_plane(params.plane_distance, 3, 200)
    plane = np.asarray(plane, dtype=np.float64)
    if len(inliers) < 3 or abs(plane[2]) < 1e-6:
        return None
    return -plane if plane[2] < 0 else plane


def plane_height(plane: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Height of the plane above world points ``xy``."""
    a, b, c, d = plane
    return -(a * xy[..., 0] + b * xy[..., 1] + d) / c


# Reference colours (sRGB) of the palette words, for naming an instance's dominant colour.
_PALETTE_HUES = (
    ("red", 0.0),
    ("orange", 30.0),
    ("yellow", 55.0),
    ("green", 120.0),
    ("cyan", 185.0),
    ("blue", 225.0),
    ("purple", 280.0),
    ("pink", 325.0),
    ("red", 360.0),
)


#: Palette words with no hue: a pixel this grey, dark or bright names no chromatic colour.
ACHROMATIC = ("black", "white", "grey")


def point_color_names(rgb: np.ndarray) -> np.ndarray:
    """The palette word of every pixel colour (``(N, 3)`` uint8 -> ``(N,)`` str), by the rule of
    :func:`color_name` applied to each pixel on its own."""
    c = rgb.reshape(-1, 3).astype(np.float64) / 255.0
    r, g, b = c[:, 0], c[:, 1], c[:, 2]
    mx, mn = c.max(axis=1), c.min(axis=1)
    sat = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1e-12), 0.0)
    span = np.maximum(mx - mn, 1e-12)
    hue = np.where(
        mx == r,
        (60.0 * (g - b) / span) % 360.0,
        np.where(mx == g, 60.0 * (b - r) / span + 120.0, 60.0 * (r - g) / span + 240.0),
    )
    hues = np.array([h for _, h in _PALETTE_HUES])
    words = np.array([w for w, _ in _PALETTE_HUES], dtype=object)
    names = words[np.argmin(np.abs(hue[:, None] - hues[None, :]), axis=1)]
    names = np.where((names == "orange") & (mx < 0.55), "brown", names)
    grey = np.where(mx < 0.25, "black", np.where(mx > 0.75, "white", "grey"))
    return np.where((sat < 0.25) | (mx < 0.12), grey, names).astype(str)


def color_name(rgb: np.ndarray) -> str:
    """The palette word for a set of pixel colours (median colour, by hue/saturation/value: the rule of
    :func:`point_color_names`)."""
    name = str(point_color_names(np.median(rgb.reshape(-1, 3), axis=0).reshape(1, 3))[0])
    assert name in COLORS
    return name
