"""Perception from RGB-D and cameras alone: a detector finds and names the objects, no simulator input.

:func:`perceive_rgbd` is the no-oracle entry point: each view (RGB, metric depth, camera) is checked
(:func:`check_view`), passed to a :class:`gsr.perception.detect.Detector` (instance masks, category,
colour, score per object), turned into a :class:`~gsr.perception.frame.Frame` whose labels carry no node
id (:func:`frame_from_detections`), and the frames are perceived together: the views are fused by 3D
overlap and parts get their parents (:mod:`gsr.perception.track`), node ids are made by perception
(``<category>_<k>``, ``<parent>/<part>_<k>``).

Bad input is a :class:`gsr.errors.GSRError` with one line: a missing depth image, an RGB/depth/camera size
mismatch, a non-numeric or wrongly shaped array. Non-finite depth (NaN, inf) and non-positive depth are
"no return"; a view with no valid depth, or a scene with nothing in it, gives an empty graph.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from gsr.perception.belief import update_belief
from gsr.perception.camera import Camera, load_camera
from gsr.perception.detect import load_detector
from gsr.perception.frame import Frame, InstanceLabel, load_depth, load_rgb
from gsr.perception.pipeline import perceive
from gsr.perception.track import Tracker

from gsr.errors import GSRError
from gsr.scene_graph import NODE_NAME, SceneGraph

if TYPE_CHECKING:
    from gsr.perception.pipeline import PerceptionParams


@dataclass(frozen=True)
class View:
    """One camera's RGB-D observation, before any segmentation."""

    rgb: np.ndarray  # HxWx3 uint8
    depth: np.ndarray  # HxW metres; 0 / NaN = no return
    camera: Camera


def check_view(rgb: Any, depth: Any, camera: Camera, where: str = "view") -> View:
    """A validated view: uint8 RGB and float32 depth (non-finite -> 0) of the camera's size."""
    if depth is None:
        raise GSRError(f"{where}: no depth image (perception needs RGB-D: pass --depth)")
    if rgb is None:
        raise GSRError(f"{where}: no RGB image")
    rgb, depth = np.asarray(rgb), np.asarray(depth)
    h, w = camera.height, camera.width
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise GSRError(f"{where}: RGB must be HxWx3, got shape {rgb.shape}")
    if depth.ndim != 2:
        raise GSRError(f"{where}: depth must be HxW, got shape {depth.shape}")
    if rgb.shape[:2] != (h, w) or depth.shape != (h, w):
        raise GSRError(
            f"{where}: sizes differ: RGB {rgb.shape[1]}x{rgb.shape[0]}, depth {depth.shape[1]}x{depth.shape[0]}, "
            f"camera {w}x{h}"
        )
    if not (np.issubdtype(depth.dtype, np.floating) or np.issubdtype(depth.dtype, np.integer)):
        raise GSRError(f"{where}: depth must be numeric metres, got dtype {depth.dtype}")
    if rgb.dtype != np.uint8:
        if not np.issubdtype(rgb.dtype, np.number):
            raise GSRError(f"{where}: RGB must be uint8, got dtype {rgb.dtype}")
        finite = np.nan_to_num(rgb.astype(np.float64), nan=0.0, posinf=255.0, neginf=0.0)
        rgb = np.clip(np.round(finite), 0, 255).astype(np.uint8)
    d = depth.astype(np.float32)
    d[~np.isfinite(d) | (d < 0)] = 0.0
    return View(rgb=np.ascontiguousarray(rgb), depth=d, camera=camera)


def frame_from_detections(view: View, detections: Sequence[Any]) -> Frame:
    """A frame whose masks are the detections (a pixel claimed twice goes to the higher score) and whose
    labels carry category, colour and the detector's score (attribute ``confidence``), never a node id."""
    h, w = view.depth.shape
    masks = np.full((h, w), -1, dtype=np.int32)
    labels: dict[int, InstanceLabel] = {}
    order = sorted(range(len(detections)), key=lambda i: float(detections[i].score))
    for k in order:
        det = detections[k]
        mask = np.asarray(det.mask, dtype=bool)
        if mask.shape != (h, w):
            raise GSRError(f"detector output: mask {k} is {mask.shape[1]}x{mask.shape[0]}, image is {w}x{h}")
        if not mask.any():
            continue
        category = str(det.category or "unknown").lower()
        if not NODE_NAME.match(category):
            category = "unknown"
        masks[mask] = k
        color = det.color if isinstance(det.color, str) and det.color else None
        attrs: dict[str, Any] = {"confidence": round(float(det.score), 3)}
        parent = (getattr(det, "attributes", None) or {}).get("parent_index")
        if isinstance(parent, int) and not isinstance(parent, bool) and 0 <= parent < len(detections):
            attrs["parent_detection"] = parent  # the detector's part -> object link (mask ids = indices)
        labels[k] = InstanceLabel(category=category, color=color, attributes=attrs)
    present = set(np.unique(masks[masks >= 0]).tolist())
    labels = {k: v for k, v in labels.items() if k in present}
    return Frame(rgb=view.rgb, depth=view.depth, masks=masks, camera=view.camera, labels=labels)


@dataclass
class Timing:
    """Seconds (wall and CPU) spent in the detector and in the geometric pipeline."""

    detect_s: float = 0.0
    detect_cpu_s: float = 0.0
    perceive_s: float = 0.0
    perceive_cpu_s: float = 0.0
    frames: int = 0


def detect_frames(views: Sequence[View], detector: Any, timing: Timing | None = None) -> list[Frame]:
    """Run the detector on every view; frames with the detections as masks and labels."""
    frames = []
    t0, c0 = time.perf_counter(), time.process_time()
    for v in views:
        if not np.any(v.depth > 0):
            dets: list[Any] = []  # nothing measured: nothing to segment
        else:
            dets = list(detector.detect(v.rgb, v.depth, v.camera))
        frames.append(frame_from_detections(v, dets))
    if timing is not None:
        timing.detect_s += time.perf_counter() - t0
        timing.detect_cpu_s += time.process_time() - c0
        timing.frames += len(views)
    return frames


def perceive_rgbd(
    views: Sequence[View],
    detector: Any,
    params: PerceptionParams | None = None,
    timing: Timing | None = None,
) -> tuple[SceneGraph, list[Frame]]:
    """Perceive views (RGB-D + camera, no masks) with ``detector``: the graph and the detected frames."""
    if not views:
        raise GSRError("perceive: no views given")
    frames = detect_frames(views, detector, timing)
    t0, c0 = time.perf_counter(), time.process_time()
    graph = perceive(frames, params)
    if timing is not None:
        timing.perceive_s += time.perf_counter() - t0
        timing.perceive_cpu_s += time.process_time() - c0
    return graph, frames


def perceive_view_files(
    rgbs: Sequence[Any],
    depths: Sequence[Any],
    cameras: Sequence[Any],
    weights: Any = None,
    previous: SceneGraph | None = None,
    params: PerceptionParams | None = None,
) -> SceneGraph:
    """Perceive one or more views given as files (``gsr perceive`` without ``--masks``).

    With ``previous`` (an earlier graph of the same scene), node ids follow it (:class:`~gsr.perception.track.Tracker`)
    and objects it explains as hidden stay in the graph (:func:`~gsr.perception.belief.update_belief`)."""
    if not rgbs:
        raise GSRError("perceive: no view given (pass --rgb, --depth and --camera)")
    if len(depths) != len(rgbs):
        raise GSRError(
            f"perceive: {len(rgbs)} RGB image(s) but {len(depths)} depth image(s); RGB-D needs one --depth per --rgb"
        )
    if len(cameras) != len(rgbs):
        raise GSRError(
            f"perceive: {len(rgbs)} RGB image(s) but {len(cameras)} camera file(s); pass one --camera per --rgb"
        )
    views = [
        check_view(load_rgb(r), load_depth(d), load_camera(c), where=str(r))
        for r, d, c in zip(rgbs, depths, cameras, strict=True)
    ]
    detector = load_detector(weights)
    graph, frames = perceive_rgbd(views, detector, params)
    if previous is not None:
        tracker = Tracker()
        tracker.issued |= {n.id for n in previous.nodes}
        graph = update_belief(previous, tracker.assign(graph, previous), frames)
    return graph
