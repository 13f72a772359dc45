"""Articulated states and functional keypoints from geometry: drawer opening, door angle, handles.

A part (label with ``parent``) is measured against its parent's *front*: the horizontal axis of the
parent's upright box that points most towards the robot base. A drawer's opening is how far its front
face stands out of the parent's front face; a door's angle is the angle between the door panel and
the parent's front plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from perception.geometry import Instance


@dataclass(frozen=True)
class ArticulationThresholds:
    """When a part counts as open, and how a handle is found without a handle mask."""

    drawer_open: float = 0.02  # m the drawer front stands out of the parent's front
    door_open: float = math.radians(10.0)  # door panel angle to the parent's front plane
    handle_protrusion: float = 0.008  # m beyond the drawer face that counts as a handle
    handle_min_points: int = 5


def front_axis(parent: Instance, robot_xy: np.ndarray) -> np.ndarray:
    """Unit horizontal axis of the parent's box that points most towards the robot."""
    to_robot = robot_xy - parent.center[:2]
    norm = np.linalg.norm(to_robot)
    to_robot = to_robot / norm if norm > 1e-9 else np.array([-1.0, 0.0])
    candidates = np.concatenate((parent.axes, -parent.axes))
    return candidates[int(np.argmax(candidates @ to_robot))]


def _front_level(points: np.ndarray, origin: np.ndarray, axis: np.ndarray) -> float:
    """How far the front-most points stand along ``axis`` (98th percentile, robust to noise)."""
    return float(np.percentile((points[:, :2] - origin) @ axis, 98.0))


def drawer_opening(part: Instance, parent: Instance, robot_xy: np.ndarray) -> float:
    """Metres the drawer's front face stands out of the parent's front face (>= 0)."""
    axis = front_axis(parent, robot_xy)
    origin = parent.center[:2]
    return max(0.0, _front_level(part.points, origin, axis) - _front_level(parent.points, origin, axis))


def door_angle(part: Instance, parent: Instance, robot_xy: np.ndarray) -> float:
    """Angle (rad, 0..pi/2) between the door panel and the parent's front plane."""
    axis = front_axis(parent, robot_xy)
    xy = part.points[:, :2] - part.points[:, :2].mean(axis=0)
    # The panel's long horizontal direction is the principal axis of its footprint.
    _, vecs = np.linalg.eigh(xy.T @ xy)
    panel = vecs[:, -1]
    lateral = np.array([-axis[1], axis[0]])
    return float(math.acos(min(1.0, abs(float(panel @ lateral)))))


def geometric_handle(
    part: Instance, parent: Instance, robot_xy: np.ndarray, th: ArticulationThresholds
) -> np.ndarray | None:
    """Centre of the points protruding from a drawer's face (its handle), if any."""
    axis = front_axis(parent, robot_xy)
    proj = (part.points[:, :2] - parent.center[:2]) @ axis
    face = float(np.median(proj[proj >= np.percentile(proj, 60.0)]))
    knob = proj > face + th.handle_protrusion
    if int(knob.sum()) < th.handle_min_points:
        return None
    return part.points[knob].mean(axis=0)


def part_states(
    instances: list[Instance], th: ArticulationThresholds, robot_xy: np.ndarray
) -> dict[str, tuple[tuple[str, ...], dict[str, float]]]:
    """States (``open``/``closed``) and measurements for every drawer and door with a perceived parent."""
    by_key = {i.key: i for i in instances}
    out: dict[str, tuple[tuple[str, ...], dict[str, float]]] = {}
    for inst in instances:
        parent = by_key.get(inst.label.parent or "")
        if parent is None:
            continue
        if inst.label.category == "drawer":
            d = drawer_opening(inst, parent, robot_xy)
            out[inst.key] = (("open",) if d > th.drawer_open else ("closed",), {"open_distance": round(d, 4)})
        elif inst.label.category == "door":
            a = door_angle(inst, parent, robot_xy)
            out[inst.key] = (("open",) if a > th.door_open else ("closed",), {"open_angle": round(a, 4)})
    return out


def keypoints(
    instances: list[Instance], segments: list[Instance], th: ArticulationThresholds, robot_xy: np.ndarray
) -> dict[str, list[tuple[str, np.ndarray]]]:
    """Functional keypoints by node: labelled keypoint segments, else geometric drawer handles."""
    out: dict[str, list[tuple[str, np.ndarray]]] = {}
    for seg in segments:
        owner = seg.label.keypoint_of or ""
        out.setdefault(owner, []).append((seg.label.name or "keypoint", seg.points.mean(axis=0)))
    by_key = {i.key: i for i in instances}
    for inst in instances:
        if inst.label.category != "drawer" or inst.key in out:
            continue
        parent = by_key.get(inst.label.parent or "")
        if parent is None:
            continue
        handle = geometric_handle(inst, parent, robot_xy, th)
        if handle is not None:
            out[inst.key] = [("handle", handle)]
    return out
