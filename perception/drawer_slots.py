"""Closed drawers that no camera shows, completed from the drawers that are seen (no-oracle path only).

A chest of drawers stacks drawers of one height in one column. The detector finds a closed drawer only
through its visible pull bar (:mod:`gsr.perception.recognize_parts`); the drawers under a pulled-out
drawer, or on a cabinet side that faces away from every camera, show a few hundred pixels of flat front or
none, and are lost. :func:`hidden_drawers` completes such a stack: for each object with a perceived drawer
that spans most of its width (the *template*: one level high, at most ``max_height_share`` of the object's
height), the object's front is the side the template stands on, and the levels of its height ``h`` repeat
at the pitch ``h (1 + gap_share)`` above and below it within the object's height range. A level that no
perceived drawer covers (half of its height) and whose front face no camera sees (under ``seen_max`` of
its front, sampled on a grid, lies at the measured depth within ``depth_tolerance`` in every view) gets a
closed drawer: the level's slab of the object's box from its front face back over ``depth_share`` of its
depth, as the template's width. A front that a camera sees flat without a bar is evidence of no drawer
there (a door, a panel), so only unobserved levels are completed.

The inferred drawer is an :class:`~gsr.perception.geometry.Instance` with synthetic points filling that
box (``views = 0``, attribute ``inferred: true``); states, levels and relations treat it as any other part
(its front is flush with the object's: closed). Objects perceived from labelled masks (a node id on the
label) are never completed.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from gsr.perception.geometry import Instance, fit_boxes

if TYPE_CHECKING:
    from gsr.perception.frame import Frame

PART = "drawer"


@dataclass(frozen=True)
class SlotParams:
    """Thresholds of the drawer-stack completion (metres or shares)."""

    min_height: float = 0.03  # a template drawer is at least this high
    max_height_share: float = 0.45  # ... and at most this share of its object's height (two levels fit)
    min_width_share: float = 0.5  # ... and spans at least this share of the object's width
    gap_share: float = 0.1  # divider between levels, as a share of the drawer height
    covered_share: float = 0.5  # a level is taken when a perceived drawer covers this share of its height
    range_margin: float = 0.01  # a level lies within the object's height range grown by this
    seen_max: float = 0.5  # a level whose front some camera sees over this share is not completed
    depth_tolerance: float = 0.02  # a front sample is seen when the measured depth is within this
    depth_share: float = 0.9  # an inferred drawer reaches back over this share of the object's depth


def hidden_drawers(
    instances: list[Instance], frames: list[Frame], params: SlotParams | None = None
) -> list[Instance]:
    """Closed drawers completing the perceived drawer stacks (new instances; ``instances`` unchanged)."""
    params = params or SlotParams()
    by_key = {i.key: i for i in instances}
    drawers: dict[str, list[Instance]] = {}
    for inst in instances:
        if inst.label.category == PART and inst.label.parent in by_key:
            drawers.setdefault(inst.label.parent, []).append(inst)
    out: list[Instance] = []
    for parent_key, parts in sorted(drawers.items()):
        parent = by_key[parent_key]
        if parent.label.id is not None or any(p.label.id is not None for p in parts):
            continue  # labelled masks: the labels say which parts exist
        out += _complete(parent, parts, frames, params)
    return out


def _front(parent: Instance, part: Instance) -> tuple[int, float]:
    """The parent's box axis (0 or 1) and side (+-1) that ``part`` stands on."""
    local = (part.center[:2] - parent.center[:2]) @ parent.axes.T
    ratio = np.abs(local) / np.maximum(parent.size[:2] / 2.0, 1e-6)
    axis = int(np.argmax(ratio))
    return axis, 1.0 if local[axis] >= 0 else -1.0


def _lateral(parent: Instance, part: Instance, axis: int) -> tuple[float, float]:
    """The part's extent across the front (parent box frame, the other horizontal axis)."""
    other = 1 - axis
    local = (part.points[:, :2] - parent.center[:2]) @ parent.axes[other]
    lo, hi = np.percentile(local, [2.0, 98.0])
    half = parent.size[other] / 2.0
    return max(float(lo), -half), min(float(hi), half)


def _template(parent: Instance, parts: list[Instance], params: SlotParams) -> Instance | None:
    """The best-evidenced perceived drawer (most points) that is one level of a column spanning the
    object's width."""
    best: Instance | None = None
    for p in parts:
        h = float(p.aabb_max[2] - p.aabb_min[2])
        if h < params.min_height or h > params.max_height_share * float(parent.size[2]):
            continue
        axis, _ = _front(parent, p)
        lo, hi = _lateral(parent, p, axis)
        if hi - lo < params.min_width_share * float(parent.size[1 - axis]):
            continue
        if best is None or len(p.points) > len(best.points):
            best = p
    return best


def _complete(
    parent: Instance, parts: list[Instance], frames: list[Frame], params: SlotParams
) -> list[Instance]:
    template = _template(parent, parts, params)
    if template is None:
        return []
    axis, side = _front(parent, template)
    lat = _lateral(parent, template, axis)
    z0, z1 = float(template.aabb_min[2]), float(template.aabb_max[2])
    h = z1 - z0
    pitch = h * (1.0 + params.gap_share)
    bottom, top = (
        float(parent.aabb_min[2]) - params.range_margin,
        float(parent.aabb_max[2]) + params.range_margin,
    )
    levels: list[tuple[float, float]] = []
    for direction in (-1, 1):
        step = 1
        while True:
            lo, hi = z0 + direction * step * pitch, z1 + direction * step * pitch
            if lo < bottom or hi > top:
                break
            levels.append((lo, hi))
            step += 1
    front = _Front(parent, axis, side, side * float(parent.size[axis]) / 2.0, lat)
    used = {p.key for p in parts}
    k = 0
    out: list[Instance] = []
    for lo, hi in sorted(levels):
        if any(_covers(p, lo, hi, h, params) for p in parts):
            continue
        if _seen_share(front, (lo, hi), frames, params) > params.seen_max:
            continue
        k += 1
        while f"{parent.key}/{PART}_{k}" in used:
            k += 1
        out.append(_drawer(front, template, (lo, hi), k, params))
    return out


def _covers(part: Instance, lo: float, hi: float, h: float, params: SlotParams) -> bool:
    """Whether a perceived drawer stands for the level [lo, hi]: it covers ``covered_share`` of the level's
    height, and it is one level high (at most 1.5 ``h``) or its centre lies in the level (two drawers read
    as one box stand for the level of their centre only)."""
    top, bottom = float(part.aabb_max[2]), float(part.aabb_min[2])
    overlap = max(min(top, hi) - max(bottom, lo), 0.0) / max(hi - lo, 1e-6)
    if overlap < params.covered_share:
        return False
    return top - bottom <= 1.5 * h or lo <= (top + bottom) / 2.0 <= hi


@dataclass(frozen=True)
class _Front:
    """A drawer stack's front: the parent's box, the axis and side it faces, the face's offset along that
    axis from the box's centre and the drawers' lateral span across it (box frame)."""

    parent: Instance
    axis: int
    side: float
    face: float
    lat: tuple[float, float]

    def to_world(self, along: np.ndarray, across: np.ndarray, z: np.ndarray) -> np.ndarray:
        return _to_world(self.parent, along, across, self.axis, z)


def _to_world(
    parent: Instance, along: np.ndarray, across: np.ndarray, axis: int, z: np.ndarray
) -> np.ndarray:
    """Points given in the parent's box frame (along the front axis, across it, height) in world xyz."""
    local = np.zeros((along.size, 2))
    local[:, axis], local[:, 1 - axis] = along, across
    xy = parent.center[:2] + local @ parent.axes
    return np.column_stack([xy, z])


def _seen_share(front: _Front, level: tuple[float, float], frames: list[Frame], params: SlotParams) -> float:
    """Largest share, over the views, of the level's front face that a camera sees at the measured depth."""
    a, z = np.meshgrid(np.linspace(front.lat[0], front.lat[1], 12), np.linspace(level[0], level[1], 5))
    pts = front.to_world(np.full(a.size, front.face), a.ravel(), z.ravel())
    normal = np.zeros(2)
    normal[front.axis] = front.side
    normal_w = np.append(normal @ front.parent.axes, 0.0)
    best = 0.0
    for f in frames:
        u, v, zc, ok = f.camera.project(pts, near=1e-3)
        ok &= (f.camera.position - pts) @ normal_w > 0  # the face turned towards this camera
        seen = np.zeros(len(pts), dtype=bool)
        d = f.depth[v[ok], u[ok]]
        seen[ok] = (d > 0) & (np.abs(d - zc[ok]) <= params.depth_tolerance)
        best = max(best, float(seen.mean()))
    return best


def _drawer(
    front: _Front, template: Instance, level: tuple[float, float], k: int, params: SlotParams
) -> Instance:
    """A closed drawer instance filling the level's slab of the parent's box behind its front face."""
    parent, face, side = front.parent, front.face, front.side
    depth = params.depth_share * float(parent.size[front.axis])
    al, ac, z = np.meshgrid(
        np.linspace(face - side * depth, face, 6), np.linspace(*front.lat, 6), np.linspace(*level, 4)
    )
    points = front.to_world(al.ravel(), ac.ravel(), z.ravel())
    # a closed drawer's front has its cabinet's colour (the template may be an open drawer's inside)
    rgb = np.repeat(np.median(parent.rgb, axis=0).astype(np.uint8)[None, :], len(points), axis=0)
    label = replace(
        template.label, color=parent.label.color, attributes={"inferred": True, "confidence": 0.0}
    )
    inst = Instance(key=f"{parent.key}/{PART}_{k}", label=label, points=points, rgb=rgb, views=0)
    fit_boxes(inst)
    return inst
