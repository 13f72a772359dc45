"""One camera's segment that holds two objects of different colours apart from each other, split.

The detector merges neighbouring segments it cannot tell apart; where two objects touch in the image it
can give them one segment: a red box and the blue box beside it, seen from the side where they meet, or
a yellow box stacked on a red box. Fusion then completes that segment with the other cameras' views of
*both* objects: one fused box spans two boxes, and everything in and on either is ``in`` it.

Colour tells such a segment apart where depth does not (the two boxes touch). The segment's points are
named by colour one by one (:func:`gsr.perception.geometry.point_color_names`); every chromatic colour
holding at least :data:`SPLIT_COLOR_SHARE` of the segment's chromatic points is a candidate piece. Two
pieces are two objects only when they lie **apart** in space: at most :data:`SPLIT_INSIDE` of either
piece's points lie inside the other's upright box. One object's colours do not lie apart so — a label on
a carton, a cube inside a box, the coloured rim of a mug all lie within the other colour's box — while two
objects side by side or stacked do. The points of no candidate colour (shadows, highlights, grey) go to
the piece whose nearest point is nearest.

The largest piece keeps the segment's label (its category, its detector link to a parent); the other
pieces become ``unknown`` objects of their own colour from the same camera, so they join whatever the
other cameras saw there and never out-vote its name (:func:`gsr.perception.track.fuse_views`). A piece
that no other camera confirms is dropped after fusion (:data:`SPLIT_PIECE`), as the segment's stray
part it was. Only objects are split (movable things and containers): not the ground, not a fixture,
not a part (a drawer's front and its carcass differ in colour by design).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import ACHROMATIC, Instance, color_name, fit_boxes, point_color_names

from gsr.categories import affordances, is_part_category

#: A colour is a candidate piece with this share of the segment's chromatic points ...
SPLIT_COLOR_SHARE = 0.2
#: ... and this many points (after down-sampling: ~4 mm apart).
SPLIT_COLOR_POINTS = 30
#: The segment is split only when this share of its points is chromatic (a grey carton's shading is not
#: two objects).
SPLIT_CHROMATIC = 0.5
#: Two candidate pieces lie apart when at most this share of either one's points is inside the other's
#: upright box (footprint and height range).
SPLIT_INSIDE = 0.2
#: Label attribute of a piece split off a segment (not the largest): dropped unless another camera saw it.
SPLIT_PIECE = "split_piece"

#: Split pieces get mask numbers from here on (negative in their keys), apart from the detector's own.
PIECE_MASK_BASE = 1_000_000

_UNKNOWN = "unknown"
_GROUNDS = frozenset({"table", "floor"})


def _object(inst: Instance) -> bool:
    cat = inst.label.category
    if inst.label.id is not None or cat in _GROUNDS or is_part_category(cat):
        return False
    aff = affordances(cat)
    return cat == _UNKNOWN or "movable" in aff or "container" in aff


def _box_of(points: np.ndarray, rgb: np.ndarray) -> Instance:
    box = Instance("piece", InstanceLabel(), points, rgb)
    fit_boxes(box)
    return box


def _inside_share(points: np.ndarray, box: Instance) -> float:
    """Share of ``points`` inside ``box``'s upright box."""
    z = points[:, 2]
    within = (z >= box.aabb_min[2]) & (z <= box.aabb_max[2])
    if not within.any():
        return 0.0
    within[within] = box.footprint_contains(points[within, :2])
    return float(within.mean())


def color_pieces(inst: Instance) -> list[np.ndarray] | None:
    """Index arrays of the colour pieces of ``inst`` (largest first) when it holds two or more objects
    apart (see the module docstring), else None."""
    names = point_color_names(inst.rgb)
    chromatic = ~np.isin(names, ACHROMATIC)
    n_chrom = int(chromatic.sum())
    if n_chrom < SPLIT_CHROMATIC * len(names) or n_chrom < 2 * SPLIT_COLOR_POINTS:
        return None
    words, counts = np.unique(names[chromatic], return_counts=True)
    cand = [
        w
        for w, c in zip(words, counts, strict=True)
        if c >= max(SPLIT_COLOR_POINTS, SPLIT_COLOR_SHARE * n_chrom)
    ]
    if len(cand) < 2:
        return None
    members = [np.nonzero(names == w)[0] for w in cand]
    boxes = [_box_of(inst.points[m], inst.rgb[m]) for m in members]
    for a in range(len(cand)):
        for b in range(a + 1, len(cand)):
            if (
                _inside_share(inst.points[members[a]], boxes[b]) > SPLIT_INSIDE
                or _inside_share(inst.points[members[b]], boxes[a]) > SPLIT_INSIDE
            ):
                return None  # one object's colours, or something inside something: not split
    from scipy.spatial import cKDTree

    owner = np.full(len(names), -1, dtype=np.int64)
    for k, m in enumerate(members):
        owner[m] = k
    rest = np.nonzero(owner < 0)[0]
    if len(rest):
        seeds = np.concatenate(members)
        _, nearest = cKDTree(inst.points[seeds]).query(inst.points[rest])
        owner[rest] = owner[seeds][nearest]
    pieces = [np.nonzero(owner == k)[0] for k in range(len(cand))]
    return sorted(pieces, key=len, reverse=True)


def _piece_key(key: str, k: int) -> str:
    """A provisional key ``unknown_f<view>m-<n>`` for piece ``k`` of the segment keyed ``<cat>_f<view>m<mask>``:
    the same camera, a mask number of its own (pieces are no parent of what the detector linked to the mask)."""
    view, _, mask = key.rpartition("_f")[2].partition("m")
    return f"{_UNKNOWN}_f{view}m-{PIECE_MASK_BASE + abs(int(mask)) * 16 + k}"


def drop_unconfirmed_pieces(fused: list[Instance]) -> list[Instance]:
    """Fused instances without the split pieces no other camera confirmed (one camera, still ``unknown``);
    the helper attribute removed from the rest."""
    out = []
    for inst in fused:
        attrs = inst.label.attributes
        if SPLIT_PIECE not in attrs:
            out.append(inst)
            continue
        if inst.views <= 1 and inst.label.category == _UNKNOWN:
            continue
        inst.label = dataclasses.replace(
            inst.label, attributes={k: v for k, v in attrs.items() if k != SPLIT_PIECE}
        )
        out.append(inst)
    return out


def split_by_color(instances: list[Instance]) -> list[Instance]:
    """Each one-camera object segment that holds objects of different colours apart, as that many
    instances (see the module docstring); the others as they are, order kept."""
    out: list[Instance] = []
    for inst in instances:
        pieces = color_pieces(inst) if _object(inst) and inst.views == 1 else None
        if not pieces:
            out.append(inst)
            continue
        for k, idx in enumerate(pieces):
            if k == 0:
                label, key = inst.label, inst.key
            else:
                label = dataclasses.replace(
                    inst.label,
                    category=_UNKNOWN,
                    attributes={
                        SPLIT_PIECE: True,
                        "confidence": inst.label.attributes.get("confidence", 1.0),
                    },
                )
                key = _piece_key(inst.key, k)
            label = dataclasses.replace(label, color=color_name(inst.rgb[idx]))
            piece = Instance(key, label, inst.points[idx], inst.rgb[idx], views=inst.views)
            fit_boxes(piece)
            out.append(piece)
    return out
