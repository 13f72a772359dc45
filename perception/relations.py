"""Spatial relations from instance geometry: ``on``, ``in``, ``adjacent`` and robot-frame directions.

All thresholds live in :class:`RelationThresholds` and are documented in docs/perception.md. Support
(``on``/``in``) is exclusive: every object gets at most one supporter, the nearest surface under it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from gsr.perception.articulation import label_affordances
from gsr.perception.geometry import Instance, box_contains_share, fit_boxes, plane_height

from gsr.categories import affordances, is_part_category

#: Categories that are the ground every other object ultimately rests on.
GROUND_CATEGORIES = frozenset({"table", "floor"})


@dataclass(frozen=True)
class RelationThresholds:
    """Distances in metres, ratios in [0, 1]."""

    on_gap: float = 0.02  # |bottom of A - top of B under A| for A on B
    on_overlap: float = 0.5  # share of A's footprint points over B's footprint
    footprint_margin: float = 0.01  # B's footprint grows by this before the overlap test
    contact_ring: float = 0.03  # B's points this far around A's footprint count as "under A"
    in_ratio: float = 0.5  # share of A's points inside B's box for A in B (B a container)
    in_rim: float = 0.01  # B's box grows upward by this (a rim seen slightly low)
    in_floor: float = 0.015  # A in B only if A's bottom is at most this below B's bottom: nothing in a
    # container lies under its floor (a neighbour on the table whose pixels widened B's box does)
    lid_clearance: float = 0.005  # A in a *closed* B only when A's top is this far under B's top (the lid)
    lid_flat_share: float = 0.8  # share of a lidded B's points around A at A's bottom (within on_gap):
    # B shows a flat top around A (a closed lid), so A rests on B, not in it
    lid_ring_points: int = 30  # fewest B points around A for that test
    adjacent_gap: float = 0.05  # footprint separation for A adjacent B (same supporter)
    direction_margin: float = 0.03  # minimum offset along the dominant axis for left_of etc.
    direction_radius: float = 0.5  # directional relations only between objects this close
    ground_margin: float = 0.05  # A rests on the ground only with its centre over the ground's footprint
    in_depth: float = 0.02  # resting on a drawer (or its cabinet) this far below its top is being in it
    opening_reach: float = 0.12  # ... in the drawer whose footprint is this close (seen only in part)
    max_support_gap: float = (
        0.25  # farther above every surface than this, A rests on nothing (held, in the air)
    )


def is_subject(inst: Instance) -> bool:
    """Objects that rest on or in something: not parts, not the ground itself."""
    cat = inst.label.category
    return inst.label.parent is None and not is_part_category(cat) and cat not in GROUND_CATEGORIES


def is_container(inst: Instance) -> bool:
    """Whether things can be *in* this instance (its category affords ``container``)."""
    return "container" in affordances(inst.label.category) or inst.label.category == "drawer"


def bottom_z(inst: Instance) -> float:
    """Robust bottom height of an instance (2nd percentile of its points' z)."""
    return float(np.percentile(inst.points[:, 2], 2.0))


#: The rim band: a container's points within this much of its top (at least; 20% of its height if more).
RIM_BAND = 0.015
#: The rim's footprint stands for the container's only when it spans this share of the box's extents
#: (walls seen all round); a drawer seen only from the front shows no rim to measure.
RIM_COVER = 0.5


def rim_box(b: Instance) -> Instance | None:
    """The upright box of a container's rim band (its wall tops, or a closed lid), or None when the band is
    too sparse or too partial to stand for the container's footprint.

    Points of a neighbour that leaked into the container's segment lie low, beside the walls: they widen
    the container's box but not its rim, which is where the walls really are."""
    z = b.points[:, 2]
    top = float(np.percentile(z, 98.0))
    band = b.points[z >= top - max(RIM_BAND, 0.2 * (top - float(np.percentile(z, 2.0))))]
    if len(band) < 20:
        return None
    rim = Instance(b.key + "#rim", b.label, band, b.rgb[: len(band)])
    fit_boxes(rim)
    # extents compared sorted: the two boxes' yaws may differ by a quarter turn
    if np.any(np.sort(rim.size[:2]) < RIM_COVER * np.sort(b.size[:2])):
        return None
    return rim


def container_footprint(b: Instance) -> Instance:
    """What decides whether a point is over a container: its rim's box where measured, else its own box."""
    rim = rim_box(b)
    return b if rim is None else rim


def in_ratio(a: Instance, b: Instance, th: RelationThresholds) -> float:
    """How much of A lies inside B's upright box (grown upward by the rim allowance), in [0, 1].

    The larger of two measures: the share of A's points inside, and A's share over B's footprint times
    the share of A's height span inside B's z range. Cameras see mostly the top of a tall object whose
    lower part B's walls hide (a bottle in a basket), so counting points undercounts; the span does not."""
    return _in_ratio(a, b, th, container_footprint(b), bottom_z(a), top_z(a))


def top_z(inst: Instance) -> float:
    """Robust top height of an instance (98th percentile of its points' z)."""
    return float(np.percentile(inst.points[:, 2], 98.0))


def _in_ratio(
    a: Instance, b: Instance, th: RelationThresholds, footprint: Instance, bottom: float, top: float
) -> float:
    """:func:`in_ratio` given B's footprint and A's robust bottom and top (computed once per instance)."""
    pts = a.points
    lo, hi = b.aabb_min[2] - 0.01, b.aabb_max[2] + th.in_rim
    inside_xy = footprint.footprint_contains(pts[:, :2], margin=0.005)
    inside_z = (pts[:, 2] >= lo) & (pts[:, 2] <= hi)
    by_points = float(np.mean(inside_xy & inside_z))
    span_inside = max(0.0, min(top, hi) - max(bottom, lo)) / max(top - bottom, 1e-3)
    return max(by_points, float(np.mean(inside_xy)) * span_inside)


def surface_under(a: Instance, b: Instance, a_bottom: float, th: RelationThresholds) -> float | None:
    """Height of B's surface under A, or None when B is not under A's footprint."""
    overlap = float(np.mean(b.footprint_contains(a.points[:, :2], margin=th.footprint_margin)))
    if overlap < th.on_overlap and not _hidden_under(a, b, a_bottom, th):
        return None
    near = a.footprint_contains(b.points[:, :2], margin=th.contact_ring)
    z = b.points[near, 2]
    z = z[z <= a_bottom + th.on_gap]  # B's points under A, not B's walls rising past A
    if z.size == 0:
        return None
    return float(np.percentile(z, 98.0)) if z.size >= 10 else float(z.max())


def _hidden_under(a: Instance, b: Instance, a_bottom: float, th: RelationThresholds) -> bool:
    """B is mostly hidden under A (a box stacked on a box): B's visible points lie under A's footprint
    and nowhere rise above A's bottom, so B's own footprint, seen only in part, cannot be trusted."""
    under = float(np.mean(a.footprint_contains(b.points[:, :2], margin=th.footprint_margin)))
    return under >= 0.8 and float(np.percentile(b.points[:, 2], 98.0)) <= a_bottom + th.on_gap


def supports(
    instances: list[Instance],
    plane: np.ndarray | None,
    th: RelationThresholds,
    closed: frozenset[str] = frozenset(),
) -> dict[str, tuple[str, str]]:
    """For each subject, its support edge ``(relation, target)``: containment first, then the top surface.

    Containers in ``closed`` (perceived closed) hold only what lies wholly under their top (the lid): what
    is seen on them rests on them. Among containers holding A the innermost (highest floor) wins.
    """
    out: dict[str, tuple[str, str]] = {}
    by_key = {i.key: i for i in instances}
    grounds = [i for i in instances if i.label.category in GROUND_CATEGORIES]
    # per-instance values every pair reads, computed once (points do not change during the call)
    memo: dict[tuple[Callable[[Instance], Any], int], Any] = {}

    def once(fn: Callable[[Instance], Any], inst: Instance) -> Any:
        key = (fn, id(inst))
        if key not in memo:
            memo[key] = fn(inst)
        return memo[key]

    for a in instances:
        if not is_subject(a):
            continue
        containers = [
            (_in_ratio(a, b, th, once(container_footprint, b), once(bottom_z, a), once(top_z, a)), b)
            for b in instances
            if b is not a
            and is_container(b)
            and b.key != a.key
            and _may_hold(a, b, closed, th)
            and once(bottom_z, a) >= once(bottom_z, b) - th.in_floor
            and (b.key in closed or not _on_flat_lid(a, b, th))
        ]
        containers = [
            (r, b)
            for r, b in containers
            if r >= th.in_ratio and not _within(b, a) and not _unconfirmed_container(b, a, by_key)
        ]
        if containers:
            # the innermost container wins (highest floor: a mug in a box that stands in a drawer is in the
            # box), then the larger ratio
            out[a.key] = ("in", max(containers, key=lambda rb: (float(rb[1].aabb_min[2]), rb[0]))[1].key)
            continue
        a_bottom = once(bottom_z, a)
        strict: list[tuple[float, str]] = []  # surfaces touching A's bottom
        below: list[tuple[float, str]] = []  # any surface under A (fallback: everything rests on something)
        for b in instances:
            if b is a or b.label.category in GROUND_CATEGORIES or not _may_support(b, a):
                continue
            top = surface_under(a, b, a_bottom, th)
            if top is None:
                continue
            below.append((top, b.key))
            if abs(a_bottom - top) <= th.on_gap:
                strict.append((top, b.key))
        for g in grounds:
            if not g.footprint_contains(a.center[None, :2], margin=th.ground_margin)[0]:
                continue  # off the table (fallen, thrown): no plane under it
            top = _ground_height(g, a, plane)
            below.append((top, g.key))
            if abs(a_bottom - top) <= th.on_gap:
                strict.append((top, g.key))
        # fallback for noise: the highest surface under A, unless A floats clearly above it (held by the
        # robot). Furniture cannot float: a fixture seen only from above (a cabinet's top) rests on the
        # highest surface under it however high its visible bottom is.
        fixed = "movable" not in affordances(a.label.category)
        near = [b for b in below if fixed or a_bottom - b[0] <= th.max_support_gap]
        pick = max(strict) if strict else (max(near) if near else None)
        if pick is not None:
            out[a.key] = ("on", pick[1])
            opening = _opening_holding(a, a_bottom, by_key.get(pick[1]), by_key, th)
            if opening is not None:
                out[a.key] = ("in", opening)
    return out


def _opening_holding(
    a: Instance, a_bottom: float, b: Instance | None, by_key: dict[str, Instance], th: RelationThresholds
) -> str | None:
    """The drawer A is in when A was found resting *on* it or on its object, below their tops.

    Nothing rests on a cabinet at a height inside its body but in one of its openings. A drawer pulled
    out is often perceived only in part (its front, the strip no object hides), so A's points need not
    lie over it: A rests on the drawer below its walls' top, or on the drawer's object (or, above its top,
    on another drawer of that object: the lower drawer reaches out under a partly seen upper one) below
    the object's top, at a height within a drawer's height range and beside that drawer."""
    if b is None or b.label.category in GROUND_CATEGORIES:
        return None
    if b.label.parent is not None:
        if is_container(b) and a_bottom < b.aabb_max[2] - th.in_depth:
            return b.key
        b = by_key.get(b.label.parent)  # above this drawer: maybe in a sibling drawer of its object
        if b is None:
            return None
    if a_bottom >= b.aabb_max[2] - th.in_depth:
        return None  # on the object's top
    best, best_d = None, th.opening_reach
    for p in by_key.values():
        if p.label.parent != b.key or not is_container(p):
            continue
        if not (p.aabb_min[2] - th.on_gap <= a_bottom <= p.aabb_max[2] - th.in_depth):
            continue
        local = np.abs((a.center[:2] - p.center[:2]) @ p.axes.T) - p.size[:2] / 2.0
        d = float(np.linalg.norm(np.maximum(local, 0.0)))
        if d <= best_d:
            best, best_d = p.key, d
    return best


def _unconfirmed_container(b: Instance, a: Instance, by_key: dict[str, Instance]) -> bool:
    """B, a detection no labelled mask names, was seen by one camera only while A was seen by several.

    A container is larger and sticks out more than what it holds: cameras that see A in it see its rim
    or walls too. One camera's segment that swallowed A's pixels and its neighbours' (a phantom `box`
    around a cube on the table) is seen by that camera alone; it holds nothing the others saw. A part
    inferred from its object (``views == 0``: a closed drawer no camera shows) is not judged here, nor is
    a drawer attached to an object that several cameras saw (:func:`attached_part`): a pulled-out drawer
    shows its front and inside to the cameras facing the object's front, often to one alone, and what
    stands in it is seen from above by others."""
    if b.label.id is not None or b.views != 1 or a.views < 2:
        return False
    parent = by_key.get(b.label.parent) if b.label.parent is not None else None
    if parent is None or parent.views < 2 or not attached_part(b, parent):
        return True
    # drawers do not nest: a "drawer" inside another part of its object and below that part's top is what
    # stands in that part (a drawer level seen inside a box read over two levels reaches the box's top)
    return any(
        p is not b
        and p.label.parent == b.label.parent
        and box_contains_share(b, p, PART_NESTED_MARGIN) >= PART_NESTED_SHARE
        and b.aabb_max[2] < p.aabb_max[2] - PART_NESTED_BELOW_TOP
        for p in by_key.values()
    )


#: A part lies within this distance (m) of its object's box (a drawer slides out of its object's front).
PART_ATTACHED_GAP = 0.02


#: A part whose box lies this much (volume share) in another part of its object's box grown by
#: PART_NESTED_MARGIN (m) is nested ...
PART_NESTED_SHARE = 0.9
PART_NESTED_MARGIN = 0.01
#: ... with its top this far (m) under that part's top: what stands in a drawer stays below its walls' top.
PART_NESTED_BELOW_TOP = 0.015


def attached_part(part: Instance, parent: Instance) -> bool:
    """The part's box touches its object's (axis-aligned boxes within :data:`PART_ATTACHED_GAP`) and its
    height centre lies in the object's height range: a drawer is a slab of its object, pulled out or not."""
    gap = np.maximum(part.aabb_min - parent.aabb_max, parent.aabb_min - part.aabb_max)
    if np.any(gap[:2] > PART_ATTACHED_GAP):
        return False
    return bool(parent.aabb_min[2] <= part.center[2] <= parent.aabb_max[2])


def _may_hold(a: Instance, b: Instance, closed: frozenset[str], th: RelationThresholds) -> bool:
    """B may contain A: B is open, or closed with A wholly under its lid (a book standing in a lidded box
    lifts the lid and shows between lid and walls; what rests on a closed lid is above B's top)."""
    if b.key not in closed:
        return True
    return float(np.percentile(a.points[:, 2], 98.0)) <= b.aabb_max[2] - th.lid_clearance


def _on_flat_lid(a: Instance, b: Instance, th: RelationThresholds) -> bool:
    """A rests on a lidded B's flat top: A's bottom is in B's upper half and nearly all of B's points
    around A's footprint lie at A's bottom.

    A second look at the lid where the whole-object cavity test (gsr.perception.articulation) calls a closed
    lid open (walls and the lid's tab seen by side cameras, depth noise): around an object *in* an open
    box B shows its floor and inner walls well below the object's visible bottom."""
    if "openable" not in label_affordances(b):
        return False
    z = b.points[a.footprint_contains(b.points[:, :2], margin=th.contact_ring), 2]
    if z.size < th.lid_ring_points:
        return False
    a_bottom = bottom_z(a)
    if a_bottom < (b.aabb_min[2] + b.aabb_max[2]) / 2:
        return False  # a flat surface in B's lower half is its floor (A is in the open box), not a lid
    return float(np.mean(np.abs(z - a_bottom) <= th.on_gap)) >= th.lid_flat_share


def _within(b: Instance, a: Instance) -> bool:
    """True when B is (mostly) inside A's box: then B cannot contain A."""
    return bool(np.all(b.size <= a.size + 0.01))


def _may_support(b: Instance, a: Instance) -> bool:
    """B can hold A up: B is not one of A's own parts and its centre is not above A's."""
    return b.label.parent != a.key and b.center[2] < a.center[2]


def _ground_height(g: Instance, a: Instance, plane: np.ndarray | None) -> float:
    """The ground's height under A: the RANSAC plane if fitted, else the ground's top points."""
    if plane is not None:
        return float(plane_height(plane, a.center[:2]))
    return float(np.percentile(g.points[:, 2], 98.0))


def footprint_gap(a: Instance, b: Instance) -> float:
    """Horizontal separation of two upright boxes along their best separating axis (0 if they overlap)."""
    gap = 0.0
    corners = {id(a): _corners(a), id(b): _corners(b)}
    for axis in (*a.axes, *b.axes):
        pa, pb = corners[id(a)] @ axis, corners[id(b)] @ axis
        gap = max(gap, pb.min() - pa.max(), pa.min() - pb.max())
    return float(gap)


def _corners(inst: Instance) -> np.ndarray:
    hx, hy = inst.size[:2] / 2.0
    local = np.array([[hx, hy], [hx, -hy], [-hx, hy], [-hx, -hy]])
    return local @ inst.axes + inst.center[:2]


def descriptive_relations(
    instances: list[Instance],
    support: dict[str, tuple[str, str]],
    th: RelationThresholds,
    world_to_robot: np.ndarray | None = None,
) -> list[tuple[str, str, str]]:
    """``adjacent`` (same supporter, close footprints) and the robot-frame directions between subjects."""
    subjects = [i for i in instances if is_subject(i)]
    rot = np.eye(3) if world_to_robot is None else np.asarray(world_to_robot)[:3, :3]
    shift = np.zeros(3) if world_to_robot is None else np.asarray(world_to_robot)[:3, 3]
    centers = {i.key: rot @ i.center + shift for i in subjects}
    edges: list[tuple[str, str, str]] = []
    for ai, a in enumerate(subjects):
        for b in subjects[ai + 1 :]:
            sa, sb = support.get(a.key), support.get(b.key)
            if sa is not None and sa == sb and footprint_gap(a, b) <= th.adjacent_gap:
                edges += [(a.key, "adjacent", b.key), (b.key, "adjacent", a.key)]
            d = centers[a.key] - centers[b.key]  # robot frame: +x forward, +y left
            if np.hypot(d[0], d[1]) > th.direction_radius:
                continue
            if abs(d[1]) >= abs(d[0]) and abs(d[1]) > th.direction_margin:
                left, right = (a, b) if d[1] > 0 else (b, a)
                edges += [(left.key, "left_of", right.key), (right.key, "right_of", left.key)]
            elif abs(d[0]) > abs(d[1]) and abs(d[0]) > th.direction_margin:
                near, far = (a, b) if d[0] < 0 else (b, a)
                edges += [(near.key, "front_of", far.key), (far.key, "behind", near.key)]
    return edges
