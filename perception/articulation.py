"""Articulated states and functional keypoints from geometry: drawer opening, door angle, handles.

A part (label with ``parent``) is measured against its parent's *front*: the side of the parent's
upright box on which the part sits (see :func:`front_axis`). A drawer's opening is how far its front
face stands out of the parent's front face; a door's angle is the angle between the door panel and
the parent's front plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from gsr.perception.geometry import Instance

from gsr.facts import node_affordances
from gsr.scene_graph import Node


def label_affordances(inst: Instance) -> frozenset[str]:
    """Affordances of an instance as the core defines them (category, plus attributes such as ``lid``)."""
    attrs = {k: v for k, v in inst.label.attributes.items() if isinstance(v, str | int | float | bool)}
    return node_affordances(Node(id=inst.key, category=inst.label.category, attributes=attrs))


@dataclass(frozen=True)
class ArticulationThresholds:
    """When a part counts as open, and how a handle is found without a handle mask.

    "Open" follows the simulator's convention (skills assets): a part is open once it is past half of
    its travel. A drawer travels about 80% of its cabinet's depth, so it is open when pulled out by
    more than 40% of the parent's depth (and at least ``drawer_open_min``); a door travels 1.6 rad, so
    it is open past 0.8 rad.
    """

    drawer_open_fraction: float = 0.4  # of the parent's depth along its front axis
    drawer_open_min: float = 0.02  # m, never "open" below this however shallow the parent
    door_open: float = 0.8  # rad between the door panel and the parent's front plane
    handle_protrusion: float = 0.008  # m beyond the drawer face that counts as a handle
    handle_min_points: int = 5
    lid_cell: float = 0.01  # m, grid cell for the top-surface test of lidded objects
    lid_depth: float = 0.025  # m below the object's top that counts as looking into a cavity
    lid_open_fraction: float = 0.15  # share of cavity cells above which a lidded object is open


def front_axis(parent: Instance, part: Instance) -> np.ndarray:
    """Unit horizontal axis of the parent's box on whose side the part sits (the parent's front).

    Drawer fronts and doors lie on (or stand out of) the parent's front face, so the box axis along
    which the part's centre is farthest out, relative to the box's half extent, is the front. This needs
    no robot pose and holds for closed parts too.
    """
    offset = (part.points[:, :2].mean(axis=0) - parent.center[:2]) @ parent.axes.T  # in box axes
    ratio = offset / np.maximum(parent.size[:2] / 2.0, 1e-6)
    k = int(np.argmax(np.abs(ratio)))
    return parent.axes[k] * (1.0 if ratio[k] >= 0 else -1.0)


def _front_level(points: np.ndarray, origin: np.ndarray, axis: np.ndarray, bin_size: float = 0.005) -> float:
    """How far the front face stands along ``axis``: the front-most slice that spans half the width.

    Slicing along the axis and requiring width keeps narrow protrusions (a pull bar standing off a
    drawer's panel) from being taken for the face.
    """
    rel = points[:, :2] - origin
    proj, lat = rel @ axis, rel @ np.array([-axis[1], axis[0]])
    width = float(np.ptp(lat))
    slices = np.floor((proj - proj.min()) / bin_size).astype(np.int64)
    order = np.argsort(slices, kind="stable")
    slices, lat_sorted, proj_sorted = slices[order], lat[order], proj[order]
    starts = np.flatnonzero(np.r_[True, slices[1:] != slices[:-1]])
    spans = np.maximum.reduceat(lat_sorted, starts) - np.minimum.reduceat(lat_sorted, starts)
    wide = np.flatnonzero(spans >= 0.5 * width)
    if wide.size == 0:  # no slice spans the width (a sliver of the part is visible): robust maximum
        return float(np.percentile(proj, 98.0))
    k = int(wide[-1])
    end = starts[k + 1] if k + 1 < len(starts) else len(proj_sorted)
    return float(np.percentile(proj_sorted[starts[k] : end], 90.0))


def drawer_opening(part: Instance, parent: Instance) -> float:
    """Metres the drawer's front face stands out of the parent's front face (>= 0)."""
    axis = front_axis(parent, part)
    origin = parent.center[:2]
    # The parent's front is its front-most points (a body has no pull bars, and a slice test would
    # fail where an arm hides part of the front); the drawer's is its widest front slice (see above).
    parent_front = float(np.percentile((parent.points[:, :2] - origin) @ axis, 98.0))
    return max(0.0, _front_level(part.points, origin, axis) - parent_front)


def parent_depth(part: Instance, parent: Instance) -> float:
    """The parent's extent along its front axis (its depth, m)."""
    axis = front_axis(parent, part)
    return float(np.ptp((parent.points[:, :2] - parent.center[:2]) @ axis))


def door_angle(part: Instance, parent: Instance) -> float:
    """Angle (rad, 0..pi/2) between the door panel and the parent's front plane."""
    axis = front_axis(parent, part)
    xy = part.points[:, :2] - part.points[:, :2].mean(axis=0)
    # The panel's long horizontal direction is the principal axis of its footprint.
    _, vecs = np.linalg.eigh(xy.T @ xy)
    panel = vecs[:, -1]
    lateral = np.array([-axis[1], axis[0]])
    return float(math.acos(min(1.0, abs(float(panel @ lateral)))))


def geometric_handle(part: Instance, parent: Instance, th: ArticulationThresholds) -> np.ndarray | None:
    """Centre of the points protruding from a drawer's face (its handle), if any."""
    axis = front_axis(parent, part)
    proj = (part.points[:, :2] - parent.center[:2]) @ axis
    face = float(np.median(proj[proj >= np.percentile(proj, 60.0)]))
    knob = proj > face + th.handle_protrusion
    if int(knob.sum()) < th.handle_min_points:
        return None
    return part.points[knob].mean(axis=0)


def cavity_fraction(inst: Instance, th: ArticulationThresholds) -> float:
    """Share of the object's footprint cells whose surface lies well below its top (an open cavity).

    A cell's surface is the median height of its points (robust to depth noise, unlike the maximum);
    the top is the 75th percentile of the cell surfaces.
    """
    cells = np.floor(inst.points[:, :2] / th.lid_cell).astype(np.int64)
    cells -= cells.min(axis=0)
    key = cells[:, 0] * (int(cells[:, 1].max()) + 1) + cells[:, 1]
    order = np.lexsort((inst.points[:, 2], key))  # by cell, then by height within the cell
    key, z = key[order], inst.points[order, 2]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, key.size])
    surface = z[starts + (counts - 1) // 2]
    top = float(np.percentile(surface, 75.0))
    return float(np.mean(surface < top - th.lid_depth))


def part_states(
    instances: list[Instance], th: ArticulationThresholds
) -> dict[str, tuple[tuple[str, ...], dict[str, float]]]:
    """States (``open``/``closed``) and measurements of drawers, doors and openable objects."""
    by_key = {i.key: i for i in instances}
    out: dict[str, tuple[tuple[str, ...], dict[str, float]]] = {}
    for inst in instances:
        parent = by_key.get(inst.label.parent or "")
        if parent is None:
            continue
        if inst.label.category == "drawer":
            d = drawer_opening(inst, parent)
            limit = max(th.drawer_open_min, th.drawer_open_fraction * parent_depth(inst, parent))
            out[inst.key] = (("open",) if d > limit else ("closed",), {"open_distance": round(d, 4)})
        elif inst.label.category == "door":
            a = door_angle(inst, parent)
            out[inst.key] = (("open",) if a > th.door_open else ("closed",), {"open_angle": round(a, 4)})
    # Openable objects: the state of their perceived door/lid part, else the top-surface test (a lid
    # covering the object leaves a flat top; an open one shows the cavity below the rim).
    for inst in instances:
        if inst.label.parent is not None or "openable" not in label_affordances(inst):
            continue
        part_state = [out[p.key][0] for p in instances if p.label.parent == inst.key and p.key in out]
        if part_state:
            out[inst.key] = (("open",) if ("open",) in part_state else ("closed",), {})
        else:
            c = cavity_fraction(inst, th)
            out[inst.key] = (("open",) if c > th.lid_open_fraction else ("closed",), {"cavity": round(c, 3)})
    return out


def keypoints(
    instances: list[Instance], segments: list[Instance], th: ArticulationThresholds
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
        handle = geometric_handle(inst, parent, th)
        if handle is not None:
            out[inst.key] = [("handle", handle)]
    return out
