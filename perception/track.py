"""Association without the simulator's ids: across cameras (3D overlap), parts to parents, and across time.

Three jobs, all on geometry that perception measured itself:

* :func:`fuse_views` merges one object's detections from several cameras into one instance: two
  detections from *different* cameras are the same object when their clouds overlap in 3D (shared 1 cm
  voxels) or, for the same category, their centres lie within half the object's width (a cube's top
  seen by one camera and its side by another share few voxels); categories that differ merge only at
  similar volumes, parts only with parts of their own category and height. One camera's detections
  merge only as duplicates (same category, boxes at IoU >= 0.5) or as pieces of the ground at one height.
  The fused category is the score-weighted vote of the views (``unknown`` only when no view named a
  category), and so is the colour.
* :func:`assign_parts` gives every part detection (a drawer, a door, a cabinet top) the object it belongs
  to: the detector's own link (``parent_index``) where it gave one, else the object (furniture,
  appliance or container) whose box holds most of the part's box. Its node id becomes
  ``<parent>/<category>_<k>`` and its ``parent`` that object, so drawer levels, openings and the
  grounder's "the bottom drawer of the cabinet" work as with labelled masks; the object's points inside
  its parts' boxes are carved out of it, and a one-view part spanning two stacked parts is dropped.
* :class:`Tracker` keeps node ids stable between observations: a node of a new observation takes the id
  of the previous belief's node it matches — first by place (same category or one of them ``unknown``,
  centres close, sizes within 2.5x), then, for what moved, by appearance (same category and colour,
  sizes within 1.6x); a part keeps its id through its
  parent and its level. Unmatched nodes get fresh ids, never one issued before.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Mapping

import numpy as np
from gsr.perception.geometry import (
    GeometryParams,
    Instance,
    box_contains_share,
    clean_points,
    color_name,
    fit_boxes,
    number_anonymous,
    point_color_names,
)
from gsr.perception.relations import RelationThresholds, bottom_z, in_ratio, is_container, rim_box, top_z
from gsr.perception.spill import carve_neighbours
from gsr.perception.view_split import drop_unconfirmed_pieces, split_by_color

from gsr.categories import affordances, is_part_category
from gsr.scene_graph import Edge, Node, SceneGraph

#: Category a detector gives to an object it cannot name (open set).
UNKNOWN = "unknown"
#: Voxel edge (m) of the 3D-overlap test between two views' clouds.
OVERLAP_VOXEL = 0.01
#: Share of the smaller cloud's voxels (after one voxel of dilation) that must be shared to merge.
MERGE_OVERLAP = 0.3
#: Two views' part detections merge only when their height ranges overlap this much (IoU): stacked
#: drawers are different parts, and a detection spanning two of them is no match for either.
PART_Z_IOU = 0.5
#: A fixture (cabinet, stove, rack: not movable) whose box lies this much inside another's of its kind is it.
FIXTURE_NESTED = 0.7
#: Ground categories: their pieces at one height are one ground, whatever the view.
GROUNDS = ("table", "floor")
_VIEW_KEY = re.compile(r"_f(\d+)m-?\d+$")


def view_of(inst: Instance) -> int:
    """The camera index an unfused instance came from (its provisional key ``<cat>_f<view>m<mask>``)."""
    m = _VIEW_KEY.search(inst.key)
    return int(m.group(1)) if m else -1


_SPAN = 1 << 20  # voxel coordinates are packed into one int64 (+-5 km at 1 cm)
_SHIFTS = np.array(
    [(dx * _SPAN + dy) * _SPAN + dz for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)],
    dtype=np.int64,
)


def _voxel_keys(points: np.ndarray) -> np.ndarray:
    """Sorted unique packed keys of the 1 cm voxels a cloud occupies."""
    cells = np.floor(points / OVERLAP_VOXEL).astype(np.int64) + _SPAN // 2
    return np.unique((cells[:, 0] * _SPAN + cells[:, 1]) * _SPAN + cells[:, 2])


def cloud_overlap(a: Instance, b: Instance) -> float:
    """Share of the smaller cloud's voxels that lie in (one voxel around) the other cloud, in [0, 1]."""
    small, large = (a, b) if len(a.points) <= len(b.points) else (b, a)
    return _key_overlap(_voxel_keys(small.points), _voxel_keys(large.points))


def _key_overlap(mine: np.ndarray, theirs: np.ndarray) -> float:
    if mine.size == 0 or theirs.size == 0:
        return 0.0
    near = (mine[:, None] + _SHIFTS[None, :]).ravel()
    pos = np.clip(np.searchsorted(theirs, near), 0, theirs.size - 1)
    hit = (theirs[pos] == near).reshape(mine.size, -1).any(axis=1)
    return float(hit.mean())


def _candidates(instances: list[Instance]) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) that may be one object: other camera, both parts or both objects, and boxes that touch
    (within a voxel) or the same category with centres within half the object's width + 1 cm; and which
    pairs pass the centre rule alone (``near``)."""
    lo = np.array([i.aabb_min for i in instances])
    hi = np.array([i.aabb_max for i in instances])
    views = np.array([view_of(i) for i in instances])
    part = np.array([is_part_category(i.label.category) for i in instances])
    cats = np.array([i.label.category for i in instances])
    g = OVERLAP_VOXEL
    touch = np.all((lo[:, None, :] - g <= hi[None, :, :]) & (lo[None, :, :] - g <= hi[:, None, :]), axis=2)
    z_overlap = np.minimum(hi[:, None, 2], hi[None, :, 2]) - np.maximum(lo[:, None, 2], lo[None, :, 2])
    centres = np.array([i.center[:2] for i in instances])
    half = np.array([0.5 * float(i.size[:2].max()) for i in instances])
    reach = np.maximum(half[:, None], half[None, :]) + 0.01
    dist = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    near = (cats[:, None] == cats[None, :]) & (z_overlap > 0) & (dist <= reach)
    allowed = (views[:, None] != views[None, :]) & (part[:, None] == part[None, :])
    # parts merge only with parts of their own kind (a drawer is no cabinet top)
    allowed &= ~(part[:, None] & part[None, :]) | (cats[:, None] == cats[None, :])
    # parts stack (drawers): two views' part detections are one part only if their heights mostly agree
    z_union = np.maximum(hi[:, None, 2], hi[None, :, 2]) - np.minimum(lo[:, None, 2], lo[None, :, 2])
    z_iou = np.clip(z_overlap, 0.0, None) / np.maximum(z_union, 1e-6)
    allowed &= ~(part[:, None] & part[None, :]) | (z_iou >= PART_Z_IOU)
    upper = np.triu(np.ones((len(instances),) * 2, dtype=bool), 1)
    return allowed & upper & (touch | near), near


#: Detections of different categories merge only when their boxes' volumes are within this factor.
CROSS_CATEGORY_VOLUME = 4.0
#: Two detections of one view are one object when they share the category and their boxes overlap this much.
SAME_VIEW_IOU = 0.5


def _same_view_duplicates(instances: list[Instance]) -> list[tuple[int, int]]:
    out = []
    for i, a in enumerate(instances):
        if is_part_category(a.label.category) or a.label.category == UNKNOWN:
            continue
        for j in range(i + 1, len(instances)):
            b = instances[j]
            if view_of(a) != view_of(b) or a.label.category != b.label.category:
                continue
            lo, hi = np.maximum(a.aabb_min, b.aabb_min), np.minimum(a.aabb_max, b.aabb_max)
            inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
            va = float(np.prod(np.maximum(a.aabb_max - a.aabb_min, 1e-3)))
            vb = float(np.prod(np.maximum(b.aabb_max - b.aabb_min, 1e-3)))
            if inter / (va + vb - inter) >= SAME_VIEW_IOU:
                out.append((i, j))
    return out


def fuse_views(instances: list[Instance], params: GeometryParams) -> list[Instance]:
    """Merge detections of one object seen by several cameras (see the module docstring); numbered keys.

    Candidate pairs are merged strongest first (voxel overlap; the centre rule counts as ``MERGE_OVERLAP``),
    and a group never takes two detections of one camera. One camera's segment holding two objects of
    different colours apart is split first (:func:`gsr.perception.view_split.split_by_color`)."""
    instances = split_by_color(instances)
    n = len(instances)
    root = list(range(n))
    views_of = {i: {view_of(inst)} for i, inst in enumerate(instances)}

    def find(i: int) -> int:
        while root[i] != i:
            root[i] = root[root[i]]
            i = root[i]
        return i

    # one object the detector split within one view (a cabinet's front and top as two segments): same
    # category, boxes overlapping at IoU >= SAME_VIEW_IOU; distinct objects of one kind do not overlap so
    for i, j in _same_view_duplicates(instances):
        ri, rj = find(i), find(j)
        if ri != rj:
            root[rj] = ri
            views_of[ri] |= views_of.pop(rj)
    pairs: list[tuple[float, int, int]] = []
    if n > 1:
        cand, near = _candidates(instances)
        keys: dict[int, np.ndarray] = {}

        def key(i: int) -> np.ndarray:
            if i not in keys:
                keys[i] = _voxel_keys(instances[i].points)
            return keys[i]

        volume = [float(np.prod(np.maximum(x.aabb_max - x.aabb_min, 0.01))) for x in instances]
        for i, j in zip(*np.nonzero(cand), strict=True):
            same = instances[i].label.category == instances[j].label.category
            agree = same and instances[i].label.category != UNKNOWN  # two views that named it alike
            if not same and max(volume[i], volume[j]) > CROSS_CATEGORY_VOLUME * min(volume[i], volume[j]):
                continue  # a small thing touching a big one (a mug by a cabinet) is not the same object
            small, large = (i, j) if len(instances[i].points) <= len(instances[j].points) else (j, i)
            overlap = _key_overlap(key(int(small)), key(int(large)))
            if near[i, j]:
                overlap = max(overlap, MERGE_OVERLAP)
            if overlap >= MERGE_OVERLAP:
                pairs.append((float(agree), overlap, int(i), int(j)))
    # views that agree on the category first, then the strongest overlap
    for _, _, i, j in sorted(pairs, reverse=True):
        ri, rj = find(i), find(j)
        if ri == rj or views_of[ri] & views_of[rj]:
            continue  # one camera's detections stay apart, even through a third view
        root[rj] = ri
        views_of[ri] |= views_of.pop(rj)
    # furniture does not nest in furniture of its kind: a cabinet piece inside a cabinet's box is that cabinet
    fixtures = [
        i
        for i, inst in enumerate(instances)
        if not is_part_category(inst.label.category)
        and inst.label.category not in GROUNDS
        and inst.label.category != UNKNOWN
        and "movable" not in affordances(inst.label.category)
    ]
    for a, i in enumerate(fixtures):
        for j in fixtures[a + 1 :]:
            x, y = instances[i], instances[j]
            if x.label.category != y.label.category:
                continue
            share = max(box_contains_share(x, y), box_contains_share(y, x))
            ri, rj = find(i), find(j)
            if ri != rj and share >= FIXTURE_NESTED:
                root[rj] = ri
                views_of[ri] |= views_of.pop(rj)
    # the ground is one surface: its pieces (split by the objects on it, in one view or several) are one
    grounds = [i for i, inst in enumerate(instances) if inst.label.category in GROUNDS]
    tops = {i: float(np.percentile(instances[i].points[:, 2], 98.0)) for i in grounds}
    for a, i in enumerate(grounds):
        for j in grounds[a + 1 :]:
            ri, rj = find(i), find(j)
            if (
                ri != rj
                and instances[i].label.category == instances[j].label.category
                and abs(tops[i] - tops[j]) <= 0.02
            ):
                root[rj] = ri
                views_of[ri] |= views_of.pop(rj)
    groups: dict[int, list[Instance]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(instances[i])
    fused = [_merge_group(g, params) for g in groups.values()]
    fused = [f for f in fused if f is not None]
    fused = carve_neighbours(fused)  # a container's cloud that spilled over its neighbours
    fused = absorb_fragments(merge_duplicates(fused, params), params)
    fused = split_disjoint(fused, params)
    stacked = join_under_stacked(split_stacked(fused, params), params)
    if {id(x) for x in stacked} != {
        id(x) for x in fused
    }:  # a container cut or joined: its new walls may have pieces to absorb
        stacked = absorb_fragments(stacked, params)
    fused = absorb_fixture_pieces(absorb_object_pieces(stacked, params), params)
    fused = drop_unconfirmed_pieces(drop_duplicate_views(fused))
    number_anonymous(fused)
    return fused


#: A one-camera piece lying on a fixture's surface: this share of its 1 cm voxels on the fixture's cloud ...
FIXTURE_PIECE_ON_SURFACE = 0.95
#: ... and its bottom this far (m) above the fixture's base (what stands beside a fixture on the table,
#: whose pixels the fixture's segment took, is not a piece of it).
FIXTURE_PIECE_ABOVE_BASE = 0.02


def absorb_fixture_pieces(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """One camera's sliver of a fixture's body (a cabinet's side or a strip of its carcass between two
    drawers, named ``milk`` or ``microwave``) joins the fixture.

    The other cameras saw that surface as the fixture's: nearly all of the piece's voxels lie on the
    fixture's cloud (several cameras saw the fixture). An object standing in an open drawer is not on the
    fixture's surface (its voxels lie above the drawer's floor, in front of the carcass or in its opening),
    the test :func:`absorb_fragments` makes for an open container's pieces; an object beside the fixture on
    the table whose pixels the fixture's segment took stands at the fixture's base and stays.

    A one-camera detection *named* a fixture (a shaded patch of a cabinet's front read as a ``microwave``,
    down to the table) joins a larger fixture that holds it (:data:`FIXTURE_PIECE_INSIDE` of its points in
    the fixture's upright box, grown :data:`FIXTURE_PIECE_MARGIN`) wherever it stands: furniture and
    appliances do not stand inside one another, and what stands in a drawer is movable."""
    fixtures = [
        f
        for f in fused
        if f.views >= 2 and not _no_object(f) and "movable" not in affordances(f.label.category)
    ]
    if not fixtures:
        return fused
    bases = [bottom_z(f) for f in fixtures]
    pieces: dict[int, Instance] = {}
    for x in fused:
        if x.views != 1 or _no_object(x, allow_unknown=True) or any(x is f for f in fixtures):
            continue
        x_bottom = bottom_z(x)
        named_fixture = _fixture(x)
        for f, f_bottom in zip(fixtures, bases, strict=True):
            if named_fixture and _fixture_holds(f, x):
                pieces[id(x)] = f
                break
            if x_bottom < f_bottom + FIXTURE_PIECE_ABOVE_BASE:
                continue
            if cloud_overlap(x, f) >= FIXTURE_PIECE_ON_SURFACE:
                pieces[id(x)] = f
                break
    if not pieces:
        return fused
    grown = _grown_by_pieces(fused, fixtures, pieces, params)
    return [grown.get(id(x), x) for x in fused if id(x) not in pieces]


#: A one-camera detection named a fixture is a piece of a larger fixture with this share of its points in the
#: fixture's upright box grown by FIXTURE_PIECE_MARGIN (m): the pull bars on a cabinet's front stand off it
#: by 1.5 cm and more (gsr.perception.recognize_parts), and a shaded patch of the front takes them along.
FIXTURE_PIECE_INSIDE = 0.9
FIXTURE_PIECE_MARGIN = 0.02


def _fixture(inst: Instance) -> bool:
    """Furniture or an appliance: a named object that is not movable (cabinet, stove, microwave, rack)."""
    return not _no_object(inst) and "movable" not in affordances(inst.label.category)


def _fixture_holds(f: Instance, x: Instance) -> bool:
    """``x`` is smaller than the fixture ``f`` and lies (``FIXTURE_PIECE_INSIDE``) in its upright box."""
    if float(np.prod(x.size)) >= float(np.prod(f.size)):
        return False
    z = x.points[:, 2]
    in_z = (z >= f.aabb_min[2] - FIXTURE_PIECE_MARGIN) & (z <= f.aabb_max[2] + FIXTURE_PIECE_MARGIN)
    inside = in_z & f.footprint_contains(x.points[:, :2], margin=FIXTURE_PIECE_MARGIN)
    return float(np.mean(inside)) >= FIXTURE_PIECE_INSIDE


#: A one-camera detection is another camera's view of an object that cameras other than its own saw when
#: this share of its 1 cm voxels lies on that object's cloud: a movable object's (no container) ...
DUPLICATE_ON_OBJECT = 0.5
#: ... or a container's, a part's or a fixture's (what stands in a container touches its walls and floor).
DUPLICATE_ON_SURFACE = 0.9


def drop_duplicate_views(fused: list[Instance]) -> list[Instance]:
    """One camera's detection of an object that other cameras saw, which fusion did not join, is dropped.

    Fusion joins views of one object by 3D overlap, but not views whose categories differ and whose sizes
    differ more than ``CROSS_CATEGORY_VOLUME`` (a camera's segment of a red cube with a strip of the box
    wall beside it, named ``mug``; a sliver of a drawer's front named ``milk``): that camera's detection
    stays an object of its own, in the container the object stands in. A detection X that one camera saw,
    most of whose voxels lie on the cloud of an object H that at least two cameras saw, **none of them X's
    camera**, is that camera's view of H: H already holds what the other cameras saw of it. The share is
    :data:`DUPLICATE_ON_OBJECT` on a movable object and :data:`DUPLICATE_ON_SURFACE` on a container, part or
    fixture (an object standing in a box against a wall lies partly on the box's cloud). Parts, grounds
    and hosts that X's camera saw (two segments of that camera: the piece rules decide) are left alone."""
    hosts = [h for h in fused if h.views >= 2 and h.label.category not in GROUNDS]
    if not hosts:
        return fused
    cams = {id(h): _cameras(h) for h in hosts}
    dropped: set[int] = set()
    for x in fused:
        if x.views != 1 or _no_object(x, allow_unknown=True):
            continue
        mine = _cameras(x)
        keys = None
        lo, hi = x.aabb_min - OVERLAP_VOXEL, x.aabb_max + OVERLAP_VOXEL
        for h in hosts:
            if h is x or not mine or mine & cams[id(h)]:
                continue
            if np.any(h.aabb_min > hi) or np.any(h.aabb_max < lo):
                continue
            movable = "movable" in affordances(h.label.category) and not is_container(h)
            need = (
                DUPLICATE_ON_OBJECT
                if movable and not is_part_category(h.label.category)
                else DUPLICATE_ON_SURFACE
            )
            keys = _voxel_keys(x.points) if keys is None else keys
            if _key_overlap(keys, _voxel_keys(h.points)) >= need:
                dropped.add(id(x))
                break
    return [x for x in fused if id(x) not in dropped]


#: A one-camera detection is a piece of a neighbouring object when this share of its points lies inside
#: the object's upright box grown by OBJECT_PIECE_MARGIN (m) ...
OBJECT_PIECE_INSIDE = 0.9
OBJECT_PIECE_MARGIN = 0.01
#: ... and its bottom lies this far (m) above the object's: a piece standing on the surface the object
#: stands on may be a neighbour (a cube against a mug whose segments took some of the cube's pixels).
OBJECT_PIECE_ABOVE_BASE = 0.01


def absorb_object_pieces(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """One camera's piece of an object that other cameras saw whole joins that object.

    A camera can split one object into two segments (a mug's body and its rim, the rim named ``box`` or
    ``cube``); fusion keeps one camera's detections apart, so the piece stays an object of its own, lying
    inside the other — and ``in`` the container the object stands in. A detection that one camera alone
    saw (X), with nearly all of its points inside the upright box of an object of its colour that several
    cameras saw (H: movable, no container — a container's pieces are its walls, :func:`absorb_fragments`)
    and smaller than it, is a piece of H: two objects do not interpenetrate, and a small object lying in a
    larger object's box of the same colour could only be inside it, which only containers allow. The piece
    must not reach down to where H stands: H's own box may be too wide, its segments having taken the
    pixels of a neighbour on the same surface."""
    hosts = [
        h
        for h in fused
        if h.views >= 2
        and h.label.color is not None
        and not _no_object(h)
        and "movable" in affordances(h.label.category)
        and not is_container(h)
    ]
    if not hosts:
        return fused
    bases = [bottom_z(h) for h in hosts]
    pieces: dict[int, Instance] = {}
    for x in fused:
        if x.views != 1 or _no_object(x, allow_unknown=True) or x.label.color is None:
            continue
        volume = float(np.prod(x.size))
        x_bottom = bottom_z(x)
        for h, h_bottom in zip(hosts, bases, strict=True):
            if h is x or h.label.color != x.label.color or volume >= float(np.prod(h.size)):
                continue
            if x_bottom < h_bottom + OBJECT_PIECE_ABOVE_BASE:
                continue  # standing where H stands: a neighbour whose pixels H's segments took
            z = x.points[:, 2]
            in_z = (z >= h.aabb_min[2] - OBJECT_PIECE_MARGIN) & (z <= h.aabb_max[2] + OBJECT_PIECE_MARGIN)
            inside = in_z & h.footprint_contains(x.points[:, :2], margin=OBJECT_PIECE_MARGIN)
            if float(np.mean(inside)) >= OBJECT_PIECE_INSIDE:
                pieces[id(x)] = h
                break
    if not pieces:
        return fused
    grown = _grown_by_pieces(fused, hosts, pieces, params)
    return [grown.get(id(x), x) for x in fused if id(x) not in pieces]


#: Two containers are stacked (one resting on the other's rim) when their footprints overlap at this IoU ...
STACK_FOOTPRINT_IOU = 0.5
#: ... and the upper one's cloud reaches at least this far above and below the lower one's top.
STACK_REACH = 0.03


def split_stacked(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """A container whose cloud took a container stacked under it is cut at that container's top.

    The detector can give a box resting on another box one segment with the box under it in some views;
    fusion then makes one container reaching from the table to the upper rim, which holds the lower box
    and everything beside it. Where another view segmented the lower container on its own (L: footprint
    overlapping, its top well below the fused one's top and well above its bottom) and the fused
    container's points below L's top have L's colour, not the container's own, those points are L's: they
    join L and the container keeps what lies above. A box standing *in* a box has the outer box's walls
    (the outer box's colour) around it below its top, so it is never cut."""
    out = list(fused)
    for u in fused:
        if not any(x is u for x in out) or not _plain_container(u):
            continue
        u_top, u_bottom = (
            float(np.percentile(u.points[:, 2], 98.0)),
            float(np.percentile(u.points[:, 2], 2.0)),
        )
        for low in out:
            if low is u or not _plain_container(low) or low.label.color in (None, u.label.color):
                continue
            top = float(np.percentile(low.points[:, 2], 98.0))
            if not (u_bottom <= top - STACK_REACH and top <= u_top - STACK_REACH):
                continue
            if _footprint_iou(u, low) < STACK_FOOTPRINT_IOU:
                continue
            below = u.points[:, 2] < top + 0.005
            if below.sum() < params.min_points or (~below).sum() < params.min_points:
                continue
            if color_name(u.rgb[below]) != low.label.color:
                continue
            upper = _combined(u, [_subset(u, ~below)], u.label.category, u.label.color, {}, params, u.views)
            lower = _join(low, _subset(u, below), params=params, keep_label=True)
            if upper is None or lower is None:
                continue
            out = [upper if x is u else lower if x is low else x for x in out]
            break
    return _split_stacked_above(out, params)


#: Points above the upper box's bottom are its own when this share of them has its colour (its walls; the
#: rest is what stands in it, seen with them).
STACK_COLOR_SHARE = 0.5


def _split_stacked_above(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """The other way round: a container whose cloud took a container stacked **on** it is cut at that
    container's bottom.

    One camera can give the upper box and the box under it one segment named by the upper box's colour;
    fusion puts it with the lower box's other views, and the lower container then reaches up to the upper
    rim and holds the upper box. Where another view segmented the upper container on its own (U: footprint
    overlapping, its bottom well above the fused one's bottom and well below its top) and the fused
    container's points above U's bottom have U's colour, not the container's own, those points are U's.
    A box standing in a box rests on the outer box's floor, not well above its bottom: never cut."""
    out = list(fused)
    for low in fused:
        if not any(x is low for x in out) or not _plain_container(low):
            continue
        l_top, l_bottom = (
            float(np.percentile(low.points[:, 2], 98.0)),
            float(np.percentile(low.points[:, 2], 2.0)),
        )
        for up in out:
            if up is low or not _plain_container(up) or up.label.color in (None, low.label.color):
                continue
            bottom = float(np.percentile(up.points[:, 2], 2.0))
            if not (l_bottom + STACK_REACH <= bottom and bottom <= l_top - STACK_REACH):
                continue
            if _footprint_iou(up, low) < STACK_FOOTPRINT_IOU:
                continue
            above = low.points[:, 2] > bottom - 0.005
            if above.sum() < params.min_points or (~above).sum() < params.min_points:
                continue
            if np.mean(point_color_names(low.rgb[above]) == up.label.color) < STACK_COLOR_SHARE:
                continue  # the container's own walls (or what stands in it), not the upper box
            lower = _combined(
                low, [_subset(low, ~above)], low.label.category, low.label.color, {}, params, low.views
            )
            upper = _join(up, _subset(low, above), params=params, keep_label=True)
            if upper is None or lower is None:
                continue
            out = [lower if x is low else upper if x is up else x for x in out]
            break
    return out


#: A container rests on what lies under it when the lower one's top is within this (m) of its bottom ...
STACK_TOP_GAP = 0.015
#: ... and over this share of the lower one's points lies inside its footprint grown by STACK_UNDER_MARGIN (m)
#: (the lower box's wall bands stand at the edge of the upper box's footprint).
STACK_UNDER_SHARE = 0.5
STACK_UNDER_MARGIN = 0.03


def join_under_stacked(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """Two containers of one colour that a container stacked on them both rests on are one.

    The box under a stacked box shows the cameras only the bands of its walls below the upper box; one
    camera sees its front wall, another its back wall, and the pieces share no voxels: fusion makes two
    containers of that colour, each completed by other views, both under the upper box, and what stands in the
    lower box is ``in`` one half or the other. A box stacked on containers (several cameras saw it) rests
    on one container: the containers of one colour (whatever each camera named them: ``box``,
    ``lidded_box``, ``cookie_box``) whose tops are at its bottom (within
    :data:`STACK_TOP_GAP`) and that lie under its footprint (:data:`STACK_UNDER_SHARE` of their points inside
    it, grown by :data:`STACK_UNDER_MARGIN`) are that one container."""
    out = list(fused)
    for up in fused:
        if not any(x is up for x in out) or not _plain_container(up) or up.views < 2:
            continue
        u_bottom = bottom_z(up)
        under: dict[str, list[Instance]] = {}
        for low in out:
            if low is up or not _plain_container(low) or low.label.color is None:
                continue
            if abs(float(np.percentile(low.points[:, 2], 98.0)) - u_bottom) > STACK_TOP_GAP:
                continue
            inside = up.footprint_contains(low.points[:, :2], margin=STACK_UNDER_MARGIN)
            if float(np.mean(inside)) > STACK_UNDER_SHARE:
                under.setdefault(low.label.color, []).append(low)
        for halves in under.values():
            if len(halves) < 2:
                continue
            halves = sorted(halves, key=lambda x: (x.views, len(x.points)), reverse=True)
            joined = _join(*halves, params=params, keep_label=True)
            if joined is None:
                continue
            at = next(k for k, x in enumerate(out) if x is halves[0])
            out[at] = joined
            out = [x for x in out if not any(x is h for h in halves[1:])]
    return out


def _plain_container(inst: Instance) -> bool:
    return not _no_object(inst) and "container" in affordances(inst.label.category)


def _subset(inst: Instance, keep: np.ndarray) -> Instance:
    part = Instance(inst.key, inst.label, inst.points[keep], inst.rgb[keep], views=inst.views)
    fit_boxes(part)
    return part


def _footprint_iou(a: Instance, b: Instance) -> float:
    lo, hi = np.maximum(a.aabb_min[:2], b.aabb_min[:2]), np.minimum(a.aabb_max[:2], b.aabb_max[:2])
    inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
    union = float(np.prod(a.aabb_max[:2] - a.aabb_min[:2]) + np.prod(b.aabb_max[:2] - b.aabb_min[:2])) - inter
    return inter / union if union > 0 else 0.0


#: Voxel edge (m) of the connectivity grid of :func:`split_disjoint`: points in voxels that touch (26
#: neighbours) are connected, so gaps under 1 cm never split an object and gaps over 2 cm always do.
SPLIT_VOXEL = 0.01
#: A piece counts as an object of its own with at least this share of the instance's points ...
SPLIT_SHARE = 0.15
#: ... and this many points ...
SPLIT_POINTS = 20
#: ... and when it spans this share of the instance's height (what the detector merged stands side by side
#: on one surface; a sliver of floor or wall seen between them does not).
SPLIT_HEIGHT = 0.6


def split_disjoint(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """Movable objects whose fused cloud falls apart into separate pieces are that many objects.

    The detector can give two same-coloured objects a little apart one segment in every view (two blue
    cubes side by side in a drawer, joined by the strip of floor between them); fusion cannot split what
    every view merged. One object's surface, seen from several cameras, is connected; a cloud with gaps of
    more than ~2 cm between object-high pieces is several objects. Pieces too small to stand for an object
    (stray floor points) go to the nearest piece kept. A piece lying on another such object's cloud (a
    neighbour's pixels that the segment took, the neighbour also fused on its own) joins that neighbour (a
    drawer or box whose segment took its contents' pixels does not count). Only anonymous detections of
    movable objects that are no containers are split (a container's walls may be seen apart across its
    opening); when every piece lies on another object, the instance stays as it is."""
    out = list(fused)
    for inst in fused:
        pieces = _disjoint_pieces(inst) if _splittable(inst) else None
        if not pieces:
            continue
        others = [x for x in out if x is not inst and _splittable(x)]
        on = [_on_another(p, others) for p in pieces]
        kept = [p for p, o in zip(pieces, on, strict=True) if o is None]
        if not kept:
            continue
        at = next(k for k, x in enumerate(out) if x is inst)
        out[at : at + 1] = kept
        now: dict[int, Instance] = {}  # a neighbour already joined by an earlier piece: its joined self
        for p, o in zip(pieces, on, strict=True):
            if o is None:
                continue
            cur = now.get(id(o), o)
            joined = _join(cur, p, params=params, keep_label=True)
            if joined is not None:
                out[next(k for k, x in enumerate(out) if x is cur)] = joined
                now[id(o)] = joined
    return out


#: A piece with this share of its voxels in (one voxel around) another object's cloud is that object.
SPLIT_ON_ANOTHER = 0.5


def _on_another(piece: Instance, others: list[Instance]) -> Instance | None:
    """The object of ``others`` whose cloud holds the piece (see :data:`SPLIT_ON_ANOTHER`), if any."""
    mine = _voxel_keys(piece.points)
    lo, hi = piece.aabb_min - OVERLAP_VOXEL, piece.aabb_max + OVERLAP_VOXEL
    for x in others:
        if np.any(x.aabb_min > hi) or np.any(x.aabb_max < lo):
            continue
        if _key_overlap(mine, _voxel_keys(x.points)) >= SPLIT_ON_ANOTHER:
            return x
    return None


def _splittable(inst: Instance) -> bool:
    cat = inst.label.category
    aff = affordances(cat)
    return (
        inst.label.id is None
        and not _no_object(inst, allow_unknown=True)
        and "container" not in aff
        and ("movable" in aff or cat == UNKNOWN)
    )


def _disjoint_pieces(inst: Instance) -> list[Instance] | None:
    """The object-sized pieces of ``inst`` as instances (see :func:`split_disjoint`), or None for one piece."""
    from scipy.ndimage import label as components

    pts = inst.points
    cells = np.floor((pts - pts.min(axis=0)) / SPLIT_VOXEL).astype(np.int64)
    shape = cells.max(axis=0) + 1
    if int(np.prod(shape)) > 200_000:
        return None  # larger than any movable object: not worth a grid
    grid = np.zeros(shape, dtype=bool)
    grid[tuple(cells.T)] = True
    labels, n = components(grid, structure=np.ones((3, 3, 3), dtype=bool))
    if n < 2:
        return None
    of_point = labels[tuple(cells.T)] - 1
    z = pts[:, 2]
    z_lo, z_hi = float(np.percentile(z, 2.0)), float(np.percentile(z, 98.0))
    span = max(z_hi - z_lo, 1e-3)
    keep = []
    for c in range(n):
        mine = of_point == c
        count = int(mine.sum())
        if count < max(SPLIT_POINTS, SPLIT_SHARE * len(pts)):
            continue
        zc = z[mine]
        if float(zc.max() - zc.min()) >= SPLIT_HEIGHT * span:
            keep.append(c)
    if len(keep) < 2:
        return None
    # every point to its piece, or (a small piece's) to the nearest kept piece's centre
    centres = np.array([pts[of_point == c].mean(axis=0) for c in keep])
    near = np.argmin(np.linalg.norm(pts[:, None, :] - centres[None, :, :], axis=2), axis=1)
    assign = np.array([keep.index(c) if c in keep else -1 for c in range(n)])[of_point]
    assign = np.where(assign >= 0, assign, near)
    pieces = []
    for k in range(len(keep)):
        mine = assign == k
        piece = Instance(f"{inst.key}#{k}", inst.label, pts[mine], inst.rgb[mine], views=inst.views)
        fit_boxes(piece)
        pieces.append(piece)
    return pieces


def _aabb_iou(a: Instance, b: Instance) -> float:
    lo, hi = np.maximum(a.aabb_min, b.aabb_min), np.minimum(a.aabb_max, b.aabb_max)
    inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
    va = float(np.prod(np.maximum(a.aabb_max - a.aabb_min, 1e-3)))
    vb = float(np.prod(np.maximum(b.aabb_max - b.aabb_min, 1e-3)))
    return inter / (va + vb - inter)


def _same_kind_of_thing(a: Instance, b: Instance) -> bool:
    """One category, or two containers (an open lidded box's inside read as a plain box)."""
    if a.label.category == b.label.category:
        return True
    return "container" in affordances(a.label.category) and "container" in affordances(b.label.category)


def merge_duplicates(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """Fused objects of one category (or two containers) whose boxes overlap at IoU >= ``SAME_VIEW_IOU``
    are one object.

    Fusion never puts two detections of one camera in a group, so a camera that split a box in two (its
    walls and its floor) leaves two groups, each completed by other views: two nearly identical boxes.
    Two distinct objects of one kind cannot share most of their volume (a box inside a box is smaller)."""
    out = list(fused)
    merged = True
    while merged:
        merged = False
        for i, a in enumerate(out):
            if _no_object(a):
                continue
            for j in range(i + 1, len(out)):
                b = out[j]
                if _same_kind_of_thing(a, b) and _aabb_iou(a, b) >= SAME_VIEW_IOU:
                    joined = _join(a, b, params=params)
                    out = [x for k, x in enumerate(out) if k not in (i, j)]
                    if joined is not None:
                        out.append(joined)
                    merged = True
                    break
            if merged:
                break
    return out


#: A one-camera detection is a piece of an open container (an inner wall or a corner the detector split
#: off) when this share of its voxels lies in (one voxel around) the container's cloud ...
FRAGMENT_OVERLAP = 0.75
#: ... nearly all of its points lie in the container's box (grown 1 cm) ...
FRAGMENT_INSIDE = 0.9
#: ... its centre is inside the container's rim, and it has a wall's extent: it reaches this far below the
#: container's floor (down to the table, as the outer walls do) or up into the rim band (or to within 1 cm
#: of the rim).
FRAGMENT_BELOW_FLOOR = 0.004
#: ... or, whatever its extent, nearly all of its voxels lie on the container's (other cameras') surface.
FRAGMENT_ON_SURFACE = 0.95
#: The piece's centre may lie this far outside the rim's box: a slab of an outer wall is centred on the
#: wall, half a wall's thickness (and the rim band's noise) outside the wall tops' box.
FRAGMENT_RIM_MARGIN = 0.015
#: ... or, whatever its overlap with the container's cloud (a wall face only this camera saw), it stands
#: from the container's base (its bottom at most this far above the container's) up into the rim band ...
FRAGMENT_BASE = 0.004
#: ... and this share of its points lies along the walls: within ``FRAGMENT_WALL_BAND`` inside the rim's
#: edges (or outside them). An object in a container stands on its floor, higher than the walls' base.
FRAGMENT_ALONG_WALLS = 0.9
FRAGMENT_WALL_BAND = 0.02


def absorb_fragments(fused: list[Instance], params: GeometryParams) -> list[Instance]:
    """Merge one-camera pieces of a container's own walls into the container (see the constants above).

    An object standing in a box touches the box at its bottom only, rests on the floor and stays below
    the rim; a wall piece lies along the container's surfaces, from the table (outside) or the rim down.
    Pieces must sit inside the container's rim, so a neighbour whose pixels leaked into the container's
    segment (lower than the walls, outside the rim) is no piece of it. A container whose rim is not
    measured (too few wall tops seen, or on one side only) stands for its rim with its own box, as a
    drawer does in :func:`absorb_part_fragments`: its rim's pieces (a wall top split off by one camera)
    are still pieces of it."""
    containers = [c for c in fused if not _no_object(c) and "container" in affordances(c.label.category)]
    if not containers:
        return fused
    pieces = _wall_pieces(fused, containers, lambda c: c if (r := rim_box(c)) is None else r)
    if not pieces:
        return fused
    grown = _grown_by_pieces(fused, containers, pieces, params)
    return [grown.get(id(x), x) for x in fused if id(x) not in pieces]


def _grown_by_pieces(
    instances: list[Instance], containers: list[Instance], pieces: dict[int, Instance], params: GeometryParams
) -> dict[int, Instance]:
    """Each container of ``containers`` joined with the pieces :func:`_wall_pieces` gave it (by the
    container's ``id``); a container whose join fails, or that got no piece, is not in the result."""
    grown: dict[int, Instance] = {}
    for c in containers:
        mine = [x for x in instances if pieces.get(id(x)) is c]
        if mine:
            joined = _join(c, *mine, params=params, keep_label=True)
            if joined is not None:
                grown[id(c)] = joined
    return grown


def _wall_pieces(fused: list[Instance], containers: list[Instance], rim_of) -> dict[int, Instance]:
    """One-camera objects that are pieces of a container's walls (see :func:`absorb_fragments`), each to
    its container; ``rim_of(c)`` gives the box of c's rim (None: no rim to test against). A piece that
    several cameras saw joins only as a wall from the container's base up to its rim, of the container's
    colour, and only a container that more cameras saw than the piece (a box stacked on a box leaves the
    lower box's wall corners to two cameras, which name them ``mug``)."""
    pieces: dict[int, Instance] = {}
    for x in fused:
        if _no_object(x, allow_unknown=True):
            continue
        for c in sorted(containers, key=lambda c: float(np.prod(c.size))):
            if c is x or float(np.prod(x.size)) >= float(np.prod(c.size)) or id(c) in pieces:
                continue
            # several cameras' piece: only a wall of the container's own colour from its base to its rim
            # (seen by more cameras than the piece: one camera's phantom container absorbs nothing real)
            several = x.views != 1
            if several and (x.label.color is None or x.label.color != c.label.color or c.views <= x.views):
                continue
            lo, hi = c.aabb_min - 0.01, c.aabb_max + 0.01
            if float(np.mean(np.all((x.points >= lo) & (x.points <= hi), axis=1))) < FRAGMENT_INSIDE:
                continue
            rim = rim_of(c)
            if rim is None or not rim.footprint_contains(x.center[None, :2], margin=FRAGMENT_RIM_MARGIN)[0]:
                continue
            x_bottom, c_bottom = bottom_z(x), bottom_z(c)
            # up into the rim band (a measured rim's lower edge) or to within 1 cm of the top
            reach = rim.aabb_max[2] - 0.01 if rim is c else min(rim.aabb_min[2], rim.aabb_max[2] - 0.01)
            to_rim = x.aabb_max[2] >= reach
            if (
                to_rim
                and x.aabb_max[2] <= rim.aabb_max[2] + 0.01  # a wall does not rise above its rim
                and x_bottom <= c_bottom + FRAGMENT_BASE
                and along_walls(x, rim) >= FRAGMENT_ALONG_WALLS
            ):
                pieces[id(x)] = c  # a wall from the container's base to its rim
                break
            if several:
                continue
            wall_like = x_bottom < c_bottom - FRAGMENT_BELOW_FLOOR or to_rim
            overlap = cloud_overlap(x, c)
            if (wall_like and overlap >= FRAGMENT_OVERLAP) or overlap >= FRAGMENT_ON_SURFACE:
                pieces[id(x)] = c
                break
    return pieces


def along_walls(x: Instance, rim: Instance) -> float:
    """Share of x's points lying along the walls of a container whose rim (or own) box is ``rim``: within
    :data:`FRAGMENT_WALL_BAND` inside the nearest edge of its footprint, or outside it."""
    local = np.abs((x.points[:, :2] - rim.center[:2]) @ rim.axes.T) - rim.size[:2] / 2.0
    return float(np.mean(np.max(local, axis=1) >= -FRAGMENT_WALL_BAND))


#: A one-camera object in a container whose top reaches within this much (m) of the container's top ...
WALL_PIECE_TOP = 0.01
#: ... spanning this share of the container's height (a wall runs from the floor to the rim) ...
WALL_PIECE_SPAN = 0.5
#: ... with this share of its points along the container's walls (:func:`along_walls`) is a wall piece.
WALL_PIECE_ALONG = 0.5


def drop_wall_pieces(instances: list[Instance], th: RelationThresholds) -> list[Instance]:
    """One camera's detection lying in a container (the ``in`` test of :func:`gsr.perception.relations.
    supports`: ``in_ratio``, its bottom not under the container's floor), reaching the container's top
    (within :data:`WALL_PIECE_TOP`), as tall as a wall (:data:`WALL_PIECE_SPAN` of the container's height)
    and lying along its walls (:data:`WALL_PIECE_ALONG`) is a piece of the container's walls that no piece
    rule joined, and is dropped.

    What stands in a container stays below its walls' top: the walls hide it from the side cameras
    unless it rises above them, and then the other cameras see it too. A band of wall from the floor to
    the rim seen by one camera alone (a lidded box's side named ``cookie_box``, whose measured top is the
    open lid's tab; a drawer's side named ``milk``) lies along the walls and reaches the top. Anonymous
    detections only (no labelled mask); parts and grounds are never dropped. Call after the parts have
    their objects (drawers are containers)."""
    containers = [c for c in instances if is_container(c) and c.label.category not in GROUNDS]
    if not containers:
        return instances
    tops = {id(c): top_z(c) for c in containers}
    rims = {id(c): (c if (r := rim_box(c)) is None else r) for c in containers}
    dropped: set[int] = set()
    for x in instances:
        if x.views != 1 or x.label.id is not None or x.label.parent is not None:
            continue
        if is_part_category(x.label.category) or x.label.category in GROUNDS:
            continue
        x_top = x_bottom = None
        for c in containers:
            if c is x or float(np.prod(x.size)) >= float(np.prod(c.size)):
                continue
            if np.any(x.aabb_min > c.aabb_max + 0.01) or np.any(x.aabb_max < c.aabb_min - 0.01):
                continue
            x_top = top_z(x) if x_top is None else x_top
            if x_top < tops[id(c)] - WALL_PIECE_TOP or x.size[2] < WALL_PIECE_SPAN * c.size[2]:
                continue
            x_bottom = bottom_z(x) if x_bottom is None else x_bottom
            if x_bottom < bottom_z(c) - th.in_floor or in_ratio(x, c, th) < th.in_ratio:
                continue
            if along_walls(x, rims[id(c)]) >= WALL_PIECE_ALONG:
                dropped.add(id(x))
                break
    return [x for x in instances if id(x) not in dropped] if dropped else instances


def absorb_part_fragments(
    instances: list[Instance], parts: list[Instance], params: GeometryParams
) -> list[Instance]:
    """Merge one-camera pieces of a drawer's walls, read as objects (a pulled drawer's side seen as a
    ``cabinet``), into the drawer (in place; the same test as :func:`absorb_fragments`, the drawer's box
    standing for its rim where the rim is not measured: a drawer seen from the front shows none); the
    parts after the merge."""
    present = {id(i) for i in instances}
    live = [p for p in parts if id(p) in present]
    # a "drawer" lying inside another part is no drawer (drawers do not nest; objects in a drawer read
    # as one): it absorbs nothing
    drawers = [p for p in live if is_container(p) and not any(q is not p and _inside(p, q) for q in live)]
    if not drawers:
        return parts
    pieces = _wall_pieces(instances, drawers, lambda c: c if (r := rim_box(c)) is None else r)
    if not pieces:
        return parts
    grown = _grown_by_pieces(instances, drawers, pieces, params)
    instances[:] = [grown.get(id(x), x) for x in instances if id(x) not in pieces]
    return [grown.get(id(p), p) for p in parts]


def _no_object(inst: Instance, allow_unknown: bool = False) -> bool:
    """Parts, grounds (and ``unknown`` unless allowed) are not candidates for these merges."""
    cat = inst.label.category
    return is_part_category(cat) or cat in GROUNDS or (cat == UNKNOWN and not allow_unknown)


def _join(*insts: Instance, params: GeometryParams, keep_label: bool = False) -> Instance | None:
    """One instance from already fused ones: provenance united, category and colour voted (or the
    first one's with ``keep_label``), points re-gridded."""
    first = insts[0]
    members = tuple(m for i in insts for m in i.label.attributes.get(MEMBERS, ()))
    parents = tuple(m for i in insts for m in i.label.attributes.get(PARENT_MEMBERS, ()))
    group = list(insts)
    category = first.label.category if keep_label else (_vote(group, "category") or first.label.category)
    color = first.label.color if keep_label else _vote(group, "color")
    cameras = {m.split("m")[0] for m in members if m.startswith("f")}
    provenance = {MEMBERS: members, PARENT_MEMBERS: parents}
    views = len(cameras) or sum(g.views for g in group)
    return _combined(first, group, category, color, provenance, params, views)


def _combined(
    base: Instance,
    group: list[Instance],
    category: str,
    color: str | None,
    provenance: dict,
    params: GeometryParams,
    views: int,
) -> Instance | None:
    """``group``'s points as one instance under ``base``'s key and label (category, colour and provenance
    set, the highest confidence kept), re-gridded; None when too few points remain."""
    scores = [
        float(s)
        for s in (g.label.attributes.get("confidence") for g in group)
        if isinstance(s, int | float) and not isinstance(s, bool)
    ]
    attrs = {**base.label.attributes, **provenance}
    if scores:
        attrs["confidence"] = round(max(scores), 3)
    label = dataclasses.replace(base.label, category=category, color=color, attributes=attrs)
    points = np.concatenate([g.points for g in group])
    rgb = np.concatenate([g.rgb for g in group])
    # each cloud is already cleaned of outliers: only the voxel grid is re-applied
    points, rgb = clean_points(points, rgb, dataclasses.replace(params, outlier_neighbors=len(points)))
    if len(points) < params.min_points:
        return None
    inst = Instance(base.key, label, points, rgb, views=views)
    fit_boxes(inst)
    return inst


def _vote(group: list[Instance], key: str) -> str | None:
    weights: dict[str, float] = {}
    for inst in group:
        value = inst.label.category if key == "category" else inst.label.color
        if value is None:
            continue
        score = inst.label.attributes.get("confidence", 1.0)
        w = (float(score) if isinstance(score, int | float) else 1.0) * len(inst.points)
        weights[value] = weights.get(value, 0.0) + w
    if key == "category" and len(weights) > 1:
        weights.pop(UNKNOWN, None)  # a view that named the object beats one that could not
    return max(sorted(weights), key=lambda v: weights[v]) if weights else None


#: Helper label attributes (provenance for parent links); removed before nodes are made.
MEMBERS, PARENT_MEMBERS, PARENT_DETECTION = "_members", "_parent_members", "parent_detection"


def _provenance(group: list[Instance]) -> dict[str, tuple[str, ...]]:
    """The detections (``f<view>m<mask>``) a fused instance is made of, and those its parts named as parent."""
    members, parents = [], []
    for g in group:
        m = _VIEW_KEY.search(g.key)
        tag = g.key[m.start() + 1 :] if m else g.key
        members.append(tag)
        p = g.label.attributes.get(PARENT_DETECTION)
        if isinstance(p, int) and not isinstance(p, bool) and m:
            parents.append(f"f{m.group(1)}m{p}")
    return {MEMBERS: tuple(members), PARENT_MEMBERS: tuple(parents)}


def _merge_group(group: list[Instance], params: GeometryParams) -> Instance | None:
    if len(group) == 1:
        g = group[0]
        g.label = dataclasses.replace(g.label, attributes={**g.label.attributes, **_provenance(group)})
        return g
    base = group[0]
    category = _vote(group, "category") or base.label.category
    color = _vote(group, "color")
    return _combined(base, group, category, color, _provenance(group), params, sum(g.views for g in group))


#: A part belongs to the object whose box holds at least this share of the part's box (grown 2 cm).
PART_IN_PARENT = 0.5
_PART_MARGIN = 0.02


def assign_parts(
    instances: list[Instance],
    grounds: Iterable[str] = ("table", "floor"),
    params: GeometryParams | None = None,
) -> None:
    """Give anonymous part instances their parent object and ``<parent>/<category>_<k>`` keys (in place);
    parts spanning two stacked levels are dropped (:func:`spanning_parts`) and pieces of one part that
    different cameras saw apart are joined (:func:`join_part_halves`)."""
    ground = frozenset(grounds)
    objects = [
        i
        for i in instances
        if not is_part_category(i.label.category)
        and i.label.category not in ground
        and i.label.category != UNKNOWN
        and can_have_parts(i.label.category)
    ]
    counts: dict[tuple[str, str], int] = {}
    adopted: list[Instance] = []
    by_member = {m: i for i in objects for m in i.label.attributes.get(MEMBERS, ())}
    for part in instances:
        if part.label.id is not None or part.label.parent is not None:
            continue
        if not is_part_category(part.label.category):
            continue
        # the detector's own link (its parent's detection in the same view), by majority over the views
        named = [by_member[m] for m in part.label.attributes.get(PARENT_MEMBERS, ()) if m in by_member]
        if named:
            best = max(named, key=lambda o: (named.count(o), float(o.size.prod())))
            _adopt(part, best, counts)
            adopted.append(part)
            continue
        best, share = None, PART_IN_PARENT
        for obj in objects:
            s = box_contains_share(part, obj, _PART_MARGIN)
            if s > share or (best is not None and s == share and obj.size.prod() > best.size.prod()):
                best, share = obj, s
        if best is not None:
            _adopt(part, best, counts)
            adopted.append(part)
    spanning = spanning_parts(instances) | whole_body_drawers(instances)
    if spanning:
        instances[:] = [i for i in instances if id(i) not in spanning]
    adopted = join_part_halves(instances, adopted, params or GeometryParams())
    adopted = absorb_part_fragments(instances, adopted, params or GeometryParams())
    carve_parts(instances, adopted)
    for inst in instances:  # provenance was only needed here
        attrs = inst.label.attributes
        if any(k in attrs for k in (MEMBERS, PARENT_MEMBERS, PARENT_DETECTION)):
            kept = {k: v for k, v in attrs.items() if k not in (MEMBERS, PARENT_MEMBERS, PARENT_DETECTION)}
            inst.label = dataclasses.replace(inst.label, attributes=kept)


#: Parts whose box is larger than this share of their object's box are not carved out of it (a detector
#: calling a whole cabinet seen from one side its "top" is a misread, not a part).
PART_CARVE_MAX = 0.3


def carve_parts(instances: list[Instance], parts: list[Instance], margin: float = 0.03) -> None:
    """Remove from each parent the points inside its detected parts' boxes (grown by ``margin``).

    A camera whose detector saw no drawer leaves the pulled-out drawer in the cabinet's segment; fused,
    the cabinet's front would then be the drawer's front and every drawer would measure closed."""
    present = {id(i) for i in instances}
    keep = {id(p) for p in parts if id(p) in present}
    by_key = {i.key: i for i in instances}
    for parent_key in {p.label.parent for p in parts if id(p) in keep}:
        parent = by_key.get(parent_key or "")
        if parent is None:
            continue
        inside = np.zeros(len(parent.points), dtype=bool)
        volume = float(np.prod(np.maximum(parent.aabb_max - parent.aabb_min, 1e-3)))
        for p in parts:
            if float(np.prod(np.maximum(p.aabb_max - p.aabb_min, 1e-3))) > PART_CARVE_MAX * volume:
                continue  # a "part" as large as its object is the object misread, not a part to carve
            if id(p) in keep and p.label.parent == parent_key:
                lo, hi = p.aabb_min - margin, p.aabb_max + margin
                inside |= np.all((parent.points >= lo) & (parent.points <= hi), axis=1)
        if inside.any() and (~inside).sum() >= max(8, 0.3 * len(inside)):
            parent.points, parent.rgb = parent.points[~inside], parent.rgb[~inside]
            fit_boxes(parent)


def can_have_parts(category: str) -> bool:
    """Furniture and appliances have parts (drawers, doors), and so do movable containers (a lidded box's
    lid, a caddy's compartments); a movable non-container (a bottle, a mug) has none."""
    aff = affordances(category)
    return "movable" not in aff or "container" in aff


def _adopt(part: Instance, parent: Instance, counts: dict[tuple[str, str], int]) -> None:
    k = counts[(parent.key, part.label.category)] = counts.get((parent.key, part.label.category), 0) + 1
    part.label = dataclasses.replace(part.label, parent=parent.key)
    part.key = f"{parent.key}/{part.label.category}_{k}"


def _z_iou(a: Instance, b: Instance) -> float:
    """Intersection over union of two height ranges."""
    overlap = min(a.aabb_max[2], b.aabb_max[2]) - max(a.aabb_min[2], b.aabb_min[2])
    union = max(a.aabb_max[2], b.aabb_max[2]) - min(a.aabb_min[2], b.aabb_min[2])
    return max(float(overlap), 0.0) / max(float(union), 1e-6)


def spanning_parts(instances: list[Instance]) -> set[int]:
    """Part detections that read two stacked parts as one (two drawers in one box): a part whose height
    range holds the centres of two other, shorter parts of the same parent. Dropped when it was seen by one
    camera, or when those parts lie at two distinct levels (height ranges at IoU < ``PART_Z_IOU``) and one
    of them was seen by as many cameras as it: the levels are then better evidenced than the tall box,
    which would only blur their openings and put their contents in one drawer."""
    out: set[int] = set()
    parts = [i for i in instances if i.label.parent is not None and is_part_category(i.label.category)]
    for p in parts:
        inside = [
            q
            for q in parts
            if q is not p
            and q.label.parent == p.label.parent
            and p.aabb_min[2] - 0.005 <= q.center[2] <= p.aabb_max[2] + 0.005
            and q.size[2] < 0.75 * p.size[2]
        ]
        if len(inside) < 2:
            continue
        if p.views == 1:
            out.add(id(p))
            continue
        levels = [(q, r) for k, q in enumerate(inside) for r in inside[k + 1 :] if _z_iou(q, r) < PART_Z_IOU]
        if any(max(q.views, r.views) >= p.views for q, r in levels):
            out.add(id(p))
    return out


#: A drawer is a slab of its object: one this share of its object's height or taller is the body misread.
DRAWER_HEIGHT_SHARE = 0.75


def whole_body_drawers(instances: list[Instance]) -> set[int]:
    """Drawer detections as tall as (``DRAWER_HEIGHT_SHARE`` of) the object they were given: the body of
    an object read as a drawer (a wine rack's lower frame), whose measured "opening" is only where the
    body's front happens to be seen. A chest's drawers stack, each a share of its height."""
    by_key = {i.key: i for i in instances}
    out: set[int] = set()
    for p in instances:
        parent = by_key.get(p.label.parent or "")
        if p.label.category != "drawer" or parent is None:
            continue
        if float(p.size[2]) >= DRAWER_HEIGHT_SHARE * float(parent.size[2]):
            out.add(id(p))
    return out


#: Pieces of one part from different cameras are joined when their boxes are at most this far apart.
PART_JOIN_GAP = 0.01


def _cameras(inst: Instance) -> set[str]:
    """The cameras (``f<view>``) whose detections make up a fused instance."""
    return {m.split("m")[0] for m in inst.label.attributes.get(MEMBERS, ()) if m.startswith("f")}


def _box_gap(a: Instance, b: Instance) -> float:
    """Largest per-axis separation of two axis-aligned boxes (0 or less when they overlap)."""
    return float(np.max(np.maximum(a.aabb_min - b.aabb_max, b.aabb_min - a.aabb_max)))


#: A part whose box lies this much inside another's is a piece of it, whatever its height range.
PART_NESTED = 0.9


#: ... and covers at most this share of its footprint: a part as wide and deep as the box it lies in is one
#: level of a box that spans two (the upper drawer in a two-level box), not a piece of it.
PART_PIECE_FOOTPRINT = 0.5


def _inside(a: Instance, b: Instance) -> bool:
    """A's box lies (``PART_NESTED``) inside B's and is a piece of it, not one of its levels."""
    if float(np.prod(a.size[:2])) > PART_PIECE_FOOTPRINT * float(np.prod(b.size[:2])):
        return False
    return box_contains_share(a, b) >= PART_NESTED


def _nested(a: Instance, b: Instance) -> bool:
    return _inside(a, b) or _inside(b, a)


#: A part at the level of another part of its object (height ranges at IoU >= this) ...
CONTENT_Z_IOU = 0.6
#: ... whose box lies this much inside the other's is what stands in that part, not a part of its own.
CONTENT_INSIDE = 0.9


def _content_read_as_part(a: Instance, b: Instance) -> Instance | None:
    """The one of two same-camera parts that lies at the other's level (``CONTENT_Z_IOU``), its box wholly
    (``CONTENT_INSIDE``) in the other's and seen by no more cameras: drawers do not nest, so it is the
    objects in the outer drawer read as a drawer. None when neither is."""
    if _z_iou(a, b) < CONTENT_Z_IOU:
        return None
    for inner, outer in ((a, b), (b, a)):
        if (
            inner.views <= outer.views
            and box_contains_share(inner, outer) >= CONTENT_INSIDE
            and float(np.prod(inner.size)) < float(np.prod(outer.size))
        ):
            return inner
    return None


def join_part_halves(
    instances: list[Instance], parts: list[Instance], params: GeometryParams
) -> list[Instance]:
    """Join pieces of one part that different cameras saw apart (in place); the parts left.

    One camera sees a pulled drawer's left half (the rest hidden by what stands in it), another its right
    half: the two clouds share few voxels, so fusion keeps two drawers at one level. Two parts are pieces
    of one when they have the same parent and category, come from disjoint cameras (one camera's segments
    stay apart: it would have shown two drawers side by side as two), lie at one level (height ranges at
    IoU >= ``PART_Z_IOU``, the rule of fusion, or one box >= ``PART_NESTED`` inside the other) and their
    boxes touch (within ``PART_JOIN_GAP``). A join
    whose box would reach into a neighbouring level (hold the centre of another part of the parent that
    lies at another level) is refused: a two-level box never absorbs a drawer. A one-camera part inside
    another part of its kind that the same camera saw is dropped (drawers do not nest: it is what stands in
    the drawer, read as a drawer)."""
    present = {id(i) for i in instances}
    out = [p for p in parts if id(p) in present]

    def reaches_other_level(lo: np.ndarray, hi: np.ndarray, skip: tuple[Instance, ...]) -> bool:
        return any(
            q.label.parent == skip[0].label.parent
            and all(q is not s for s in skip)
            and lo[2] + 0.005 < q.center[2] < hi[2] - 0.005
            and all(_z_iou(q, s) < PART_Z_IOU for s in skip)
            for q in out
        )

    merged = True
    while merged:
        merged = False
        for i, a in enumerate(out):
            for b in out[i + 1 :]:
                if a.label.parent is None or a.label.parent != b.label.parent:
                    continue
                if a.label.category != b.label.category:
                    continue
                if _cameras(a) & _cameras(b):
                    # one camera's part inside another part of its own (drawers do not nest): the objects
                    # in the drawer read as one more drawer; dropped when no other camera saw it
                    inner = a if _inside(a, b) else b if _inside(b, a) else None
                    if inner is None or inner.views != 1:
                        # ... or at its level wholly inside it and seen by no more cameras (the objects
                        # standing in a pulled drawer, read as a drawer by the cameras that saw the drawer)
                        inner = _content_read_as_part(a, b)
                    if inner is not None:
                        instances[:] = [x for x in instances if x is not inner]
                        out = [x for x in out if x is not inner]
                        merged = True
                        break
                    continue
                level = _z_iou(a, b) >= PART_Z_IOU or _nested(a, b)
                if not level or _box_gap(a, b) > PART_JOIN_GAP:
                    continue
                lo, hi = np.minimum(a.aabb_min, b.aabb_min), np.maximum(a.aabb_max, b.aabb_max)
                if reaches_other_level(lo, hi, (a, b)):
                    continue
                large, small = (a, b) if len(a.points) >= len(b.points) else (b, a)
                joined = _join(large, small, params=params, keep_label=True)
                if joined is None:
                    continue
                joined.key = large.key
                instances[:] = [joined if x is large else x for x in instances if x is not small]
                out = [joined if x is large else x for x in out if x is not small]
                merged = True
                break
            if merged:
                break
    return out


# ------------------------------------------------------------------ identities across time


def rename_graph(graph: SceneGraph, mapping: Mapping[str, str]) -> SceneGraph:
    """The graph with node ids (and parents, edge ends) renamed by ``mapping``; unmapped ids stay."""
    if not mapping or all(k == v for k, v in mapping.items()):
        return graph

    def r(x: str | None) -> str | None:
        return None if x is None else mapping.get(x, x)

    nodes = tuple(
        sorted(
            (n.model_copy(update={"id": r(n.id), "parent": r(n.parent)}) for n in graph.nodes),
            key=lambda n: n.id,
        )
    )
    edges = tuple(
        sorted(
            {Edge(source=r(e.source), relation=e.relation, target=r(e.target)) for e in graph.edges},  # type: ignore[arg-type]
            key=Edge.key,
        )
    )
    return graph.model_copy(update={"nodes": nodes, "edges": edges})


def _center(n: Node) -> np.ndarray | None:
    if n.bbox is not None:
        lo, hi = n.bbox.min, n.bbox.max
        return np.array([(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, (lo.z + hi.z) / 2])
    if n.pose is not None:
        p = n.pose.position
        return np.array([p.x, p.y, p.z])
    return None


def _size(n: Node) -> np.ndarray:
    a = n.attributes
    vals = [a.get("size_x"), a.get("size_y"), a.get("size_z")]
    return np.array([float(v) if isinstance(v, int | float) else 0.0 for v in vals])


def _same_kind(a: Node, b: Node) -> bool:
    """Same category, either ``unknown``, or two containers (a lidded box with its lid off looks like a box)."""
    if a.category == b.category or UNKNOWN in (a.category, b.category):
        return True
    return "container" in affordances(a.category) and "container" in affordances(b.category)


#: Centres closer than this (m, plus half the larger footprint) are the same object staying in place.
TRACK_REACH = 0.03
#: Sizes within this ratio (each of x/y sorted, and z) count as similar for re-identification after a move.
SIZE_RATIO = 1.6
#: ... and for staying in place (looser: another camera angle or the arm's shadow changes the visible part).
PLACE_SIZE_RATIO = 2.5


def _place_cost(new: Node, old: Node) -> float | None:
    c1, c2 = _center(new), _center(old)
    if c1 is None or c2 is None or not _same_kind(new, old) or not _similar_size(new, old, PLACE_SIZE_RATIO):
        return None
    reach = 0.5 * float(max(_size(new)[:2].max(), _size(old)[:2].max())) + TRACK_REACH
    d = float(np.linalg.norm(c1 - c2))
    return d if d <= reach else None


def _size_ratio(new: Node, old: Node) -> np.ndarray | None:
    s1, s2 = _size(new), _size(old)
    if not (s1.any() and s2.any()):
        return None
    a = np.concatenate([np.sort(s1[:2]), s1[2:]]) + 0.01
    b = np.concatenate([np.sort(s2[:2]), s2[2:]]) + 0.01
    return np.maximum(a / b, b / a)


def _similar_size(new: Node, old: Node, limit: float) -> bool:
    ratio = _size_ratio(new, old)
    return ratio is None or float(ratio.max()) <= limit


def _look_cost(new: Node, old: Node) -> float | None:
    if new.category != old.category:
        return None
    if new.attributes.get("color") != old.attributes.get("color"):
        return None
    ratio = _size_ratio(new, old)
    if ratio is None:
        return 1.0
    if float(ratio.max()) > SIZE_RATIO:
        return None
    return float(np.abs(np.log(ratio)).sum())


#: A part keeps its id only across height ranges overlapping at least this much (IoU): a drawer slides
#: out and back at its own height; the level's rank is no identity (it shifts when the cameras find one
#: drawer more or fewer).
PART_TRACK_Z_IOU = 0.3


#: Extra cost of a part only remembered (not seen in the last look): what the cameras saw last is the
#: better evidence (a drawer pushed shut is the drawer seen open a moment ago, not a two-level box seen
#: once at the start).
REMEMBERED_PART_COST = 0.5


def _part_cost(new: Node, old: Node) -> float | None:
    """Cost of ``new`` being the part ``old`` (same parent and category assumed): height-range mismatch
    plus half the centre distance, plus ``REMEMBERED_PART_COST`` for a part not seen in the last look; by
    level rank and distance when either has no box."""
    c1, c2 = _center(new), _center(old)
    d = float(np.linalg.norm(c1 - c2)) if c1 is not None and c2 is not None else 1.0
    if new.bbox is None or old.bbox is None:
        return d + (0.0 if new.attributes.get("level") == old.attributes.get("level") else 10.0)
    overlap = min(new.bbox.max.z, old.bbox.max.z) - max(new.bbox.min.z, old.bbox.min.z)
    union = max(new.bbox.max.z, old.bbox.max.z) - min(new.bbox.min.z, old.bbox.min.z)
    z_iou = max(overlap, 0.0) / max(union, 1e-6)
    if z_iou < PART_TRACK_Z_IOU:
        return None
    stale = REMEMBERED_PART_COST if old.attributes.get("observed") is False else 0.0
    return (1.0 - z_iou) + 0.5 * d + stale


def _assign(pairs: dict[tuple[str, str], float]) -> dict[str, str]:
    """Minimum-cost one-to-one assignment over the allowed (new, old) pairs."""
    if not pairs:
        return {}
    from scipy.optimize import linear_sum_assignment

    news = sorted({a for a, _ in pairs})
    olds = sorted({b for _, b in pairs})
    big = 1e6
    cost = np.full((len(news), len(olds)), big)
    for (a, b), c in pairs.items():
        cost[news.index(a), olds.index(b)] = c
    rows, cols = linear_sum_assignment(cost)
    return {news[r]: olds[c] for r, c in zip(rows, cols, strict=True) if cost[r, c] < big}


class Tracker:
    """Stable node ids across observations (see the module docstring)."""

    def __init__(self) -> None:
        self.issued: set[str] = set()

    def assign(self, observed: SceneGraph, previous: SceneGraph | None) -> SceneGraph:
        """``observed`` with each node renamed to the id of the previous node it matches, or a fresh id."""
        prev = [n for n in (previous.nodes if previous is not None else ()) if not n.attributes.get("map")]
        new = [n for n in observed.nodes if not n.attributes.get("map")]
        mapping: dict[str, str] = {}
        # the ground is one surface: the one ground of a kind now is the one before, wherever the cameras
        # saw its middle (an arm over the table shifts what is visible of it)
        for kind in GROUNDS:
            now_g = [n for n in new if n.parent is None and n.category == kind]
            old_g = [n for n in prev if n.parent is None and n.category == kind]
            if len(now_g) == 1 and len(old_g) == 1:
                mapping[now_g[0].id] = old_g[0].id
        # objects first: by place, then by appearance for what moved
        new_obj = [n for n in new if n.parent is None and n.id not in mapping]
        old_obj = [n for n in prev if n.parent is None and n.id not in mapping.values()]
        for cost in (_place_cost, _look_cost):
            free_old = [o for o in old_obj if o.id not in mapping.values()]
            pairs = {
                (n.id, o.id): c
                for n in new_obj
                if n.id not in mapping
                for o in free_old
                if (c := cost(n, o)) is not None
            }
            mapping.update(_assign(pairs))
        # parts: same (renamed) parent and category, then the same height range (a drawer slides, its
        # height stays), else the nearest
        parts_new = [n for n in new if n.parent is not None]
        old_parts = [n for n in prev if n.parent is not None]
        pairs = {}
        for n in parts_new:
            parent = mapping.get(n.parent or "")
            for o in old_parts:
                if o.parent != parent or o.category != n.category:
                    continue
                if (cost := _part_cost(n, o)) is not None:
                    pairs[(n.id, o.id)] = cost
        mapping.update(_assign(pairs))
        # fresh ids for the rest (objects before parts, so a part follows its parent's new id)
        taken = set(mapping.values())
        for n in sorted(new, key=lambda n: (n.parent is not None, n.id)):
            if n.id in mapping:
                continue
            parent = mapping.get(n.parent or "", n.parent)
            stem = n.id.rsplit("/", 1)[-1]
            stem = _NUMBERED.sub("", stem) or n.category
            prefix = f"{parent}/" if parent is not None else ""
            k = 1
            while f"{prefix}{stem}_{k}" in self.issued | taken:
                k += 1
            mapping[n.id] = f"{prefix}{stem}_{k}"
            taken.add(mapping[n.id])
        self.issued |= set(mapping.values())
        return rename_graph(observed, mapping)


_NUMBERED = re.compile(r"_\d+$")
