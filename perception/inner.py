"""Objects standing in an open container that the detector left in the container's segment.

Seen from a high camera through a container's mouth, an object standing on the container's floor shows
its top and the upper part of its sides, but the detector can give those pixels to the container: an
object of the container's own colour has no colour edge against the walls around it (a blue cube in a
blue box), and a small, partly hidden one of another colour (a mug's rim over a wall) has too few pixels
to be a segment of its own. Fusion then makes one container whose cloud holds the object, and the object
and its ``in`` relation are lost.

An empty open container's cloud is its walls (their tops, inner and outer faces: all within a wall's
thickness of the rim's edges or outside them) and its floor (at its base). Its points **away from the
walls and above the floor** are what stands in it. :func:`objects_in_containers` cuts them out: for each
open container (a measured rim: :func:`gsr.perception.relations.rim_box`) that several cameras saw, the
points of its cloud inside the rim's footprint shrunk by :data:`INNER_WALL_BAND`, higher than
:data:`INNER_ABOVE_FLOOR` over its base and on no other object's cloud, fall into pieces on a 1 cm grid
(26-connected); each piece with :data:`INNER_MIN_POINTS` points, spanning :data:`INNER_MIN_HEIGHT` in
height, reaching down to within :data:`INNER_REACH_FLOOR` of the floor band (it stands on the floor, not
hangs from a wall) and with the footprint of an object (:data:`INNER_MIN_WIDTH`) becomes an object of its
own, named by the coarse shape rule (:func:`gsr.perception.recognize.shape_category` on its extent and
its height over the container's base; ``unknown`` where the rule names nothing) with its colour from its
points, and leaves the container's cloud.

The converse, :func:`pieces_in_closed`: nothing inside a *closed* container is seen, so one camera's
detection of the container's colour that lies in it is a patch of the container itself, and is dropped.
And :func:`parts_read_on_objects`: one camera's drawer lying inside another object's box (of its colour,
several cameras) is that object read as a part, and is dropped.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import Instance, box_contains_share, color_name, fit_boxes, point_color_names
from gsr.perception.recognize import shape_category
from gsr.perception.relations import bottom_z, is_container, rim_box, top_z
from gsr.perception.track import GROUNDS, UNKNOWN, cloud_overlap
from scipy import ndimage

from gsr.categories import affordances, is_part_category

#: Points within this much (m) inside the rim's edges, or outside them, are the walls.
INNER_WALL_BAND = 0.02
#: Points less than this much (m) above the container's base are its floor.
INNER_ABOVE_FLOOR = 0.015
#: A container whose rim band has more than this share of its points away from the walls is closed (a lid).
INNER_MOUTH_COVERED = 0.3
#: Grid of the connectivity test (m).
INNER_VOXEL = 0.01
#: A piece kept as an object has at least this many points ...
INNER_MIN_POINTS = 30
#: ... spans at least this much (m) in height ...
INNER_MIN_HEIGHT = 0.01
#: ... and reaches down to within this much (m) above the floor band (it stands on the floor) ...
INNER_REACH_FLOOR = 0.02
#: ... and is at least this wide (m) along its shorter horizontal extent.
INNER_MIN_WIDTH = 0.02
#: A piece with this share of its 1 cm voxels on another object's cloud is that object's.
INNER_ON_OTHER = 0.5


def _next_unknown(instances: list[Instance]) -> int:
    n = 0
    for x in instances:
        head, _, tail = x.key.partition("_")
        if head == UNKNOWN and tail.isdigit():
            n = max(n, int(tail))
    return n + 1


def _pieces(points: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the 26-connected pieces of ``points`` on the :data:`INNER_VOXEL` grid."""
    cells = np.floor(points / INNER_VOXEL).astype(np.int64)
    lo = cells.min(axis=0)
    cells -= lo
    shape = tuple(int(v) + 1 for v in cells.max(axis=0))
    grid = np.zeros(shape, dtype=bool)
    grid[cells[:, 0], cells[:, 1], cells[:, 2]] = True
    labels, n = ndimage.label(grid, structure=np.ones((3, 3, 3), dtype=bool))
    of_point = labels[cells[:, 0], cells[:, 1], cells[:, 2]]
    return [np.nonzero(of_point == k)[0] for k in range(1, n + 1)]


def objects_in_containers(instances: list[Instance]) -> list[Instance]:
    """New ``unknown`` objects cut out of open containers' clouds (see the module docstring); the
    containers lose those points. Anonymous (no-oracle) instances only: a labelled mask is never cut."""
    containers = [
        c
        for c in instances
        if is_container(c)
        and c.label.id is None
        and c.label.category not in GROUNDS
        and not is_part_category(c.label.category)
        and c.views >= 2
    ]
    if not containers:
        return instances
    next_id = _next_unknown(instances)
    added: list[Instance] = []
    for c in containers:
        rim = rim_box(c)
        if rim is None:
            continue
        local = np.abs((c.points[:, :2] - rim.center[:2]) @ rim.axes.T) - rim.size[:2] / 2.0
        in_band = c.points[:, 2] >= float(rim.aabb_min[2])
        if float(np.mean(np.max(local[in_band], axis=1) < -INNER_WALL_BAND)) > INNER_MOUTH_COVERED:
            continue  # the rim band is a lid or a cover over the mouth, not wall tops: a closed container
        base = bottom_z(c)
        inner = (np.max(local, axis=1) < -INNER_WALL_BAND) & (c.points[:, 2] > base + INNER_ABOVE_FLOOR)
        if int(inner.sum()) < INNER_MIN_POINTS:
            continue
        idx = np.nonzero(inner)[0]
        taken = np.zeros(len(c.points), dtype=bool)
        for piece in _pieces(c.points[idx]):
            if len(piece) < INNER_MIN_POINTS:
                continue
            sel = idx[piece]
            pts = c.points[sel]
            z = pts[:, 2]
            if float(z.max() - z.min()) < INNER_MIN_HEIGHT:
                continue
            if float(z.min()) > base + INNER_ABOVE_FLOOR + INNER_REACH_FLOOR:
                continue
            obj = Instance(
                f"{UNKNOWN}_{next_id}", InstanceLabel(category=UNKNOWN), pts, c.rgb[sel], views=c.views
            )
            fit_boxes(obj)
            if float(np.min(obj.size[:2])) < INNER_MIN_WIDTH:
                continue
            if any(
                o is not c and o.label.category not in GROUNDS and cloud_overlap(obj, o) >= INNER_ON_OTHER
                for o in instances
            ):
                continue
            names = Counter(point_color_names(obj.rgb).tolist())
            major, minor = sorted(obj.size[:2].tolist(), reverse=True)
            obj.label = InstanceLabel(
                category=shape_category(major, minor, top_z(obj) - base),
                color=names.most_common(1)[0][0],
                attributes={"inferred_from": c.key},
            )
            taken[sel] = True
            added.append(obj)
            next_id += 1
        if taken.any():
            c.points, c.rgb = c.points[~taken], c.rgb[~taken]
            fit_boxes(c)
    return instances + added if added else instances


def pieces_in_closed(
    instances: list[Instance], support: dict[str, tuple[str, str]], closed: frozenset[str]
) -> list[Instance]:
    """One camera's anonymous detection of a closed container's colour that the support test put *in*
    that container, dropped: nothing inside a closed container is seen (a lid lifted by what stands in it
    shows that object, of its own colour), so it is a patch of the container's own walls or lid that one
    camera segmented apart (a lidded box's side named ``cookie_box``). ``support``:
    :func:`gsr.perception.relations.supports` of ``instances`` with ``closed``."""
    by_key = {x.key: x for x in instances}
    dropped: set[int] = set()
    for x in instances:
        rel = support.get(x.key)
        if rel is None or rel[0] != "in" or rel[1] not in closed:
            continue
        c = by_key.get(rel[1])
        if c is None or x.views != 1 or x.label.id is not None or x.label.parent is not None:
            continue
        if is_part_category(x.label.category) or _colour(x) != _colour(c):
            continue
        dropped.add(id(x))
    return [x for x in instances if id(x) not in dropped] if dropped else instances


def _colour(x: Instance) -> str:
    """The colour word its node will carry: the label's, else named from its points."""
    return x.label.color or str(x.label.attributes.get("color") or color_name(x.rgb))


#: A one-camera part lying this share (of its box) inside another object's box is that object's view.
PART_ON_OBJECT = 0.9


def parts_read_on_objects(instances: list[Instance]) -> list[Instance]:
    """One camera's anonymous part (a drawer) whose box lies :data:`PART_ON_OBJECT` inside the box of an
    object of its colour that several cameras saw, and that is neither its parent nor a fixture or ground,
    is that camera's view of the object misread as a part (a blue lidded box beside a cabinet read as an
    open drawer of the cabinet, with what stands on the box "in" it), and is dropped: a drawer lies in its
    own cabinet, and a pulled-out one stands out in front of it, in no other object."""
    hosts = [
        o
        for o in instances
        if o.views >= 2
        and o.label.category not in GROUNDS
        and not is_part_category(o.label.category)
        and "movable" in affordances(o.label.category)
    ]
    dropped: set[int] = set()
    for p in instances:
        if p.views != 1 or p.label.id is not None or not is_part_category(p.label.category):
            continue
        for o in hosts:
            if o.key == p.label.parent or _colour(o) != _colour(p):
                continue
            if box_contains_share(p, o) >= PART_ON_OBJECT:
                dropped.add(id(p))
                break
    return [x for x in instances if id(x) not in dropped] if dropped else instances
