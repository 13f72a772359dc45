"""A container's fused cloud that spilled over its neighbours: the neighbours' points carved out of it.

One camera can give a box and what stands against it one segment (a blue mug beside a blue box, a box
beside a box of another colour seen from the side where they touch in the image); fusion completes that
segment with the other cameras' views of the box, and the container's cloud then reaches over its
neighbour. Its box, measured from that cloud, covers the neighbour, which becomes ``in`` it.

The other cameras that segmented the neighbour on its own say where it is: a fused object seen by at
least :data:`SPILL_CONFIRMED_VIEWS` cameras is an object of its own, and the container's points inside that
object's upright box are the object's surface, not the container's. They are removed from the container
(:func:`carve_neighbours`). This is safe for what really lies in the container: the walls around it stay,
so the container's extent does not change, only the object's own pixels leave the container's cloud.
What rests on the container (a box stacked on a box, a lid's handle) is not carved: its bottom is at the
container's top. A carve that would take most of the container (the container inside the object: a box
standing in a larger box, or a box on top of which the neighbour's cloud reaches) is not made; it does not
keep the other neighbours from being carved.
"""

from __future__ import annotations

import numpy as np
from gsr.perception.geometry import Instance, fit_boxes
from gsr.perception.relations import bottom_z

from gsr.categories import affordances, is_part_category

#: A neighbour is an object of its own when this many cameras saw it (one camera's segment may be a piece
#: of the container, a wall face it split off).
SPILL_CONFIRMED_VIEWS = 2
#: The neighbour's footprint grows by this (m) and its height range by SPILL_Z_MARGIN: the container's
#: camera sees the neighbour's faces that other cameras did not, a little outside their box.
SPILL_MARGIN = 0.01
SPILL_Z_MARGIN = 0.005
#: A neighbour whose bottom lies above the container's top minus this (m) rests on it: never carved.
SPILL_ON_TOP = 0.02
#: At most this share of the container's points is carved, by all neighbours together.
SPILL_MAX_SHARE = 0.5
#: A container that several cameras saw is its neighbours read as one only with this share of its points
#: in their boxes (two touching cubes of one colour read as a ``box`` by three cameras): nothing of it is
#: wall or floor of its own.
SPILL_WHOLE_SHARE = 0.9
#: A container keeps at least this many points.
SPILL_MIN_POINTS = 20

_GROUNDS = frozenset({"table", "floor"})


def _object(inst: Instance) -> bool:
    cat = inst.label.category
    return not is_part_category(cat) and cat not in _GROUNDS


def _container(inst: Instance) -> bool:
    return _object(inst) and "container" in affordances(inst.label.category)


def _neighbour_masks(container: Instance, others: list[Instance]) -> list[tuple[Instance, np.ndarray]]:
    """Each confirmed neighbour not resting on ``container``, with the mask of the container's points
    inside its box (footprint grown by SPILL_MARGIN, height range by SPILL_Z_MARGIN); empty masks left out."""
    pts = container.points
    c_top = float(np.percentile(pts[:, 2], 98.0))
    out = []
    for o in others:
        if o is container or not _object(o) or o.views < SPILL_CONFIRMED_VIEWS:
            continue
        if bottom_z(o) > c_top - SPILL_ON_TOP:
            continue  # resting on the container (or above it): its points are not in the container's cloud
        z_lo, z_hi = float(o.aabb_min[2]) - SPILL_Z_MARGIN, float(o.aabb_max[2]) + SPILL_Z_MARGIN
        near = (pts[:, 2] >= z_lo) & (pts[:, 2] <= z_hi)
        if not near.any():
            continue
        inside = np.zeros(len(pts), dtype=bool)
        inside[near] = o.footprint_contains(pts[near, :2], margin=SPILL_MARGIN)
        if inside.any():
            out.append((o, inside))
    return out


def spilled_points(container: Instance, others: list[Instance]) -> np.ndarray:
    """Boolean mask over ``container``'s points that lie inside a confirmed neighbour's box (see the
    module docstring). A neighbour whose box holds most of the container (the container inside it: a box
    in a larger box) is not carved; all False when the carve would be too large."""
    pts = container.points
    spilled = np.zeros(len(pts), dtype=bool)
    for _, inside in _neighbour_masks(container, others):
        if inside.mean() <= SPILL_MAX_SHARE:
            spilled |= inside
    if spilled.mean() > SPILL_MAX_SHARE or (~spilled).sum() < SPILL_MIN_POINTS:
        return np.zeros(len(pts), dtype=bool)
    return spilled


def neighbours_read_as_container(container: Instance, others: list[Instance]) -> bool:
    """Whether a container that one camera alone saw lies mostly (> SPILL_MAX_SHARE of its points) in the
    boxes of confirmed movable objects that are no containers, or one that several cameras saw lies in them
    whole (SPILL_WHOLE_SHARE): those objects read as one segment (a mug and the book beside it read as a
    ``box``), not a container of its own. A real container's walls
    lie outside what stands in it; a container inside a larger container, or in a fixture's box (a cube in
    a cabinet's drawer read as a ``box``), is not counted."""
    covered = np.zeros(len(container.points), dtype=bool)
    for o, inside in _neighbour_masks(container, others):
        if "movable" in affordances(o.label.category) and not _container(o):
            covered |= inside
    share = float(covered.mean())
    return share > SPILL_MAX_SHARE if container.views == 1 else share >= SPILL_WHOLE_SHARE


def carve_neighbours(fused: list[Instance]) -> list[Instance]:
    """Each container without the points it took from confirmed neighbours (a new instance where points
    were carved, the others as they are; order kept); a one-camera container that is its neighbours
    read as one (:func:`neighbours_read_as_container`) is left out."""
    out = []
    for inst in fused:
        if not _container(inst):
            out.append(inst)
            continue
        if neighbours_read_as_container(inst, fused):
            continue
        spilled = spilled_points(inst, fused)
        if not spilled.any():
            out.append(inst)
            continue
        keep = ~spilled
        carved = Instance(inst.key, inst.label, inst.points[keep], inst.rgb[keep], views=inst.views)
        fit_boxes(carved)
        out.append(carved)
    return out
