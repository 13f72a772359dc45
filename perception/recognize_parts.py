"""Articulated parts that show no boundary of their own: closed drawers found from their handles.

A closed drawer's front is flush with its cabinet's front and (in the asset library) nearly the same
colour, so no depth or colour edge separates it; its pull handle, standing off the front, does. The
recogniser labels a handle-sized segment ``drawer``; :func:`split_drawer_fronts` finds the vertical face
behind each such handle (2-8 cm behind it, on another segment: the host), cuts that face into horizontal
bands (one per handle, limits half-way between neighbouring handles' heights) and gives each band to its
drawer. Every drawer (banded or a segment of its own, e.g. an open one) gets a parent: the host of its face, or
the non-drawer segment whose box lies nearest (within ``HOST_REACH``).

An open drawer's side is inset by a centimetre from its cabinet's side and has the cabinet's colour, so
the segmenter often leaves the pulled-out drawer in the cabinet's segment (recognised as ``cabinet`` or,
for its look, ``drawer``). :func:`split_open_drawers` finds it from the geometry: a cabinet's top face
ends at its front, so what stands out beyond the top's edge, below the top, is a drawer pulled out of it
(front, side walls, inside). It becomes a drawer of its own (one per handle height when handles are seen
on it), its handles join it, and the rest of the segment is the cabinet.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from gsr.perception.segment import Segments

#: A drawer segment no larger than this (m, every extent) is a handle seen alone.
HANDLE_SIZE = 0.13
#: The face behind a handle lies this far behind it (m).
STANDOFF = (0.015, 0.08)
#: Face pixels: within this distance of the face plane (m) and normals within ~25 degrees of it.
FACE_DISTANCE = 0.015
FACE_ALIGN = 0.9
#: An open drawer's parent: the nearest other segment whose box lies within this distance (m).
HOST_REACH = 0.3
#: Segments that may hold a pulled-out drawer: recognised as one of these, at least this large (m).
DRAWER_HOSTS = ("cabinet", "drawer")
HOST_MIN_EXTENT = 0.18
#: Top face: up-facing pixels (|normal z| above TOP_UP) within TOP_BAND of the segment's top height (m).
TOP_UP = 0.9
TOP_BAND = 0.015
TOP_MIN_PIXELS = 20
#: A drawer stands out beyond the top's front edge by more than OUT_MARGIN, below the top by BELOW_TOP (m),
#: and spans at least OUT_MIN_WIDTH across the front with at least OUT_MIN_PIXELS grid pixels.
OUT_MARGIN = 0.02
BELOW_TOP = 0.015
OUT_MIN_WIDTH = 0.1
OUT_MIN_PIXELS = 25
#: Floors of stacked open drawers: up-facing 1 cm height bins with this share of the region's up-facing
#: pixels, at least FLOOR_GAP apart (m); the drawer above starts FLOOR_BELOW under its floor (its bottom).
FLOOR_SHARE = 0.2
FLOOR_GAP = 0.06
FLOOR_BELOW = 0.01
#: An attached drawer of its own segment: its bottom at least HOVER above the support, reaching back to
#: within REACH_BACK of the cabinet's front (m).
HOVER = 0.02
REACH_BACK = 0.1
#: A handle-sized piece no thicker than this (m) standing off a cabinet's face is a pull bar (cubes are not
#: that thin).
HANDLE_THICK = 0.03
#: ... and spanning at least this share of the cabinet's width (a drawer is nearly as wide as its
#: cabinet; a bowl standing in the drawer is not).
DRAWER_WIDTH = 0.6
#: Marks a handle segment merged into the drawer it belongs to (dropped from the list).
ABSORBED = "_absorbed"
#: Dark pull bars inside a cabinet segment: pixels darker than DARK_RATIO x the segment's median brightness,
#: in blobs of at least DARK_MIN_PIXELS grid pixels (blobs within HANDLE_JOIN m of each other in height and
#: HANDLE_SIZE across are one handle).
DARK_RATIO = 0.45
DARK_MIN_PIXELS = 4
HANDLE_JOIN = 0.03


@dataclass
class Part:
    """A segment-level answer: strided mask, category, scores, colour, and parent (index) if a part."""

    mask: np.ndarray
    category: str
    score: float
    color: str | None
    feature_index: int
    parent: int | None = None


def _cloud(seg: Segments, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pts = seg.points[mask]
    nrm = seg.normals[mask]
    ok = np.all(np.isfinite(pts), axis=1) & np.all(np.isfinite(nrm), axis=1)
    rows, cols = np.nonzero(mask)
    return pts[ok], nrm[ok], np.column_stack((rows[ok], cols[ok]))


def cut_dark_handles(seg: Segments, parts: list[Part]) -> list[Part]:
    """Pull bars the segmenter left in their cabinet's segment, as handle parts (category ``drawer``).

    Seen at a grazing angle a closed drawer's handle shows no depth jump against the cabinet's face, and
    the link model rightly keeps a handle with its drawer's front, which nothing separates from the
    cabinet: the handle stays in the cabinet's segment and its drawer is lost. Here the cabinet's pixels
    much darker than its median brightness are grouped into blobs; a blob that is handle-sized (at most
    ``HANDLE_SIZE`` long and ``HANDLE_THICK`` thick), lies below the cabinet's top and stands off a
    vertical face of the rest of the segment by ``STANDOFF`` becomes a handle, which
    :func:`split_drawer_fronts` then turns into a drawer with its front band."""
    from scipy.ndimage import label

    out = list(parts)
    for k, host in enumerate(parts):
        if host.category not in ("cabinet", "cabinet_top"):
            continue
        rgb = seg.rgb.astype(np.float64).mean(axis=2)
        bright = rgb[host.mask]
        if bright.size < TOP_MIN_PIXELS * 2:
            continue
        below = _top_z(seg, host.mask)
        dark = host.mask & (rgb < DARK_RATIO * float(np.median(bright)))
        blobs, n = label(dark, np.ones((3, 3), bool))
        found: list[tuple[np.ndarray, np.ndarray]] = []  # (mask, points)
        for b in range(1, n + 1):
            mask = blobs == b
            if mask.sum() < DARK_MIN_PIXELS:
                continue
            pts, _, pix = _cloud(seg, mask)
            if len(pts) < DARK_MIN_PIXELS:
                continue  # a dark blob without depth (no return): nothing to measure
            # pixels on a silhouette get depths smeared towards the background: not part of the bar
            near = np.all(np.abs(pts - np.median(pts, axis=0)) <= HANDLE_SIZE / 2, axis=1)
            pts, pix = pts[near], pix[near]
            mask = np.zeros_like(mask)
            mask[pix[:, 0], pix[:, 1]] = True
            if len(pts) < DARK_MIN_PIXELS or np.percentile(pts[:, 2], 98.0) > below:
                continue
            for i, (m, p) in enumerate(found):  # pieces of one bar (its posts, a bar broken by shading)
                both = np.vstack((p, pts))
                if abs(np.median(p[:, 2]) - np.median(pts[:, 2])) < HANDLE_JOIN and np.all(
                    np.ptp(both, axis=0) <= HANDLE_SIZE
                ):
                    found[i] = (m | mask, both)
                    break
            else:
                found.append((mask, pts))
        for mask, pts in found:
            size = np.sort(np.percentile(pts, 95.0, axis=0) - np.percentile(pts, 5.0, axis=0))
            if size[-1] > HANDLE_SIZE or size[0] > HANDLE_THICK:
                continue
            rest = host.mask & ~mask
            trial = [*out[:k], replace_mask(host, rest), *out[k + 1 :]]
            handle = Part(mask, "drawer", host.score, None, host.feature_index)
            face = _face_behind(seg, [*trial, handle], len(trial), pts)
            if face is None or face[0] != k:
                continue
            host.mask = rest
            out[k] = host
            out.append(handle)
    return out


def drop_bare_handles(seg: Segments, parts: list[Part]) -> list[Part]:
    """Give back to their host the drawers that are only a pull bar: no front band at least
    ``OUT_MIN_WIDTH`` wide joined them (the drawer's face is seen edge-on or not at all). A bar alone is a
    box a few centimetres wide that fusion keeps apart from the same drawer seen from the front (a second
    drawer node), and it says nothing about the drawer's extent (measured: docs/performance.md, Issue 22)."""
    drop = set()
    for k, part in enumerate(parts):
        if part.category != "drawer" or part.parent is None:
            continue
        pts, _, _ = _cloud(seg, part.mask)
        if len(pts) >= 3 and np.max(np.ptp(pts[:, :2], axis=0)) >= OUT_MIN_WIDTH:
            continue
        host = parts[part.parent]
        host.mask = host.mask | part.mask
        drop.add(k)
    return without_parts(parts, drop)


def without_parts(parts: list[Part], drop: set[int]) -> list[Part]:
    """``parts`` less the indices in ``drop`` (their masks already given to a host), the remaining
    parts' ``parent`` indices renumbered (a parent that was dropped becomes None)."""
    if not drop:
        return parts
    keep = [i for i in range(len(parts)) if i not in drop]
    index = {old: new for new, old in enumerate(keep)}
    for i in keep:
        if parts[i].parent is not None:
            parts[i].parent = index.get(parts[i].parent)
    return [parts[i] for i in keep]


def replace_mask(part: Part, mask: np.ndarray) -> Part:
    """A copy of ``part`` with another mask."""
    return Part(mask, part.category, part.score, part.color, part.feature_index, part.parent)


def _top_z(seg: Segments, mask: np.ndarray) -> float:
    """World z of a segment's top less ``BELOW_TOP`` (a handle hangs below its cabinet's top)."""
    pts = seg.points[mask]
    z = pts[:, 2][np.isfinite(pts[:, 2])]
    if z.size == 0:
        return np.inf
    return float(np.percentile(z, 98.0)) - BELOW_TOP


def split_drawer_fronts(seg: Segments, parts: list[Part]) -> list[Part]:
    """Give closed drawers their front bands and every drawer a parent (see the module docstring)."""
    hosts: dict[int, list[tuple[int, float, np.ndarray, np.ndarray]]] = {}
    for k, part in enumerate(parts):
        if part.category != "drawer" or part.parent is not None:  # (a pulled-out drawer has its cabinet)
            continue
        pts, _, _ = _cloud(seg, part.mask)
        if len(pts) < 3:
            continue
        extent = pts.max(axis=0) - pts.min(axis=0)
        if np.all(extent <= HANDLE_SIZE):
            face = _face_behind(seg, parts, k, pts)
            if face is not None:
                host, normal, origin = face
                hosts.setdefault(host, []).append((k, float(np.median(pts[:, 2])), normal, origin))
                part.parent = host
                continue
        part.parent = _nearest_host(seg, parts, k, pts)
    for host, handles in hosts.items():
        _cut_bands(seg, parts, host, handles)
    return parts


def _face_behind(
    seg: Segments, parts: list[Part], k: int, handle: np.ndarray
) -> tuple[int, np.ndarray, np.ndarray] | None:
    """(host index, outward face normal, a point on the face) of the vertical face behind a handle."""
    centre = np.median(handle, axis=0)
    best: tuple[int, np.ndarray, np.ndarray] | None = None
    best_n = 0
    for j, other in enumerate(parts):
        if j == k or other.category in ("drawer", "table"):
            continue
        pts, nrm, _ = _cloud(seg, other.mask)
        if len(pts) < 10:
            continue
        near = (
            (np.abs(nrm[:, 2]) < 0.3)
            & (np.linalg.norm(pts[:, :2] - centre[:2], axis=1) < 0.15)
            & (np.abs(pts[:, 2] - centre[2]) < 0.12)
        )
        if near.sum() < 5 or near.sum() <= best_n:
            continue
        normal = np.median(nrm[near], axis=0)
        normal[2] = 0.0
        length = np.linalg.norm(normal)
        if length < 0.5:
            continue
        normal /= length
        origin = np.median(pts[near], axis=0)
        if np.dot(centre - origin, normal) < 0:
            normal = -normal
        standoff = float(np.dot(centre - origin, normal))
        if STANDOFF[0] <= standoff <= STANDOFF[1]:
            best, best_n = (j, normal, origin), int(near.sum())
    return best


def _cut_bands(
    seg: Segments, parts: list[Part], host: int, handles: list[tuple[int, float, np.ndarray, np.ndarray]]
) -> None:
    """Move the host's face pixels into horizontal bands, one per handle, ordered by height."""
    pts_all = seg.points
    nrm_all = seg.normals
    handles = sorted(handles, key=lambda h: h[1])
    normal = handles[0][2]
    origin = np.mean([h[3] for h in handles], axis=0)
    hm = parts[host].mask
    with np.errstate(invalid="ignore"):
        align = np.abs(np.nan_to_num(nrm_all @ normal)) > FACE_ALIGN
        dist = np.abs(np.nan_to_num((pts_all - origin) @ normal, nan=1.0))
    face = hm & align & (dist < FACE_DISTANCE)
    if not face.any():
        return
    z = np.nan_to_num(pts_all[..., 2], nan=-1e9)
    heights = [h[1] for h in handles]
    limits = [-np.inf] + [(a + b) / 2.0 for a, b in pairwise(heights)] + [np.inf]
    for (k, _, _, _), lo, hi in zip(handles, limits[:-1], limits[1:], strict=True):
        band = face & (z >= lo) & (z < hi)
        parts[k].mask = parts[k].mask | band
        parts[host].mask = parts[host].mask & ~band


def _nearest_host(seg: Segments, parts: list[Part], k: int, pts: np.ndarray) -> int | None:
    """The non-drawer segment whose box lies nearest this drawer's centre (within ``HOST_REACH``)."""
    centre = np.median(pts, axis=0)
    best, best_d = None, HOST_REACH
    for j, other in enumerate(parts):
        if j == k or other.category in ("drawer", "table", "unknown"):
            continue
        opts, _, _ = _cloud(seg, other.mask)
        if len(opts) < 10:
            continue
        lo, hi = opts.min(axis=0), opts.max(axis=0)
        d = float(np.linalg.norm(np.maximum(0.0, np.maximum(lo - centre, centre - hi))))
        if d < best_d:
            best, best_d = j, d
    return best


def split_open_drawers(seg: Segments, parts: list[Part]) -> list[Part]:
    """Cut pulled-out drawers out of the cabinet segments that swallowed them (see the module docstring)."""
    out = list(parts)
    for k, host in enumerate(parts):
        if host.category not in DRAWER_HOSTS:
            continue
        found = _protrusion(seg, host.mask)
        if found is None:
            continue
        drawer_mask, axis, front = found
        handles = _handles_on(seg, out, k, drawer_mask, axis, front)
        floors = _floor_levels(seg, drawer_mask)
        if len(floors) >= 2:  # stacked open drawers: each one's floor is its bottom
            bands = _bands_at(seg, drawer_mask, [f - FLOOR_BELOW for f in floors[1:]])
        else:
            bands = _height_bands(seg, drawer_mask, [h for _, h in handles])
        host.mask = host.mask & ~drawer_mask
        if host.category == "drawer":  # the whole was read as a drawer: what stays is its cabinet
            host.category = "cabinet"
        first = len(out)
        for band in bands:
            out.append(Part(band, "drawer", host.score, host.color, host.feature_index, parent=k))
        heights = [float(np.nanmedian(seg.height[b])) for b in bands]
        for j, height in handles:  # a handle joins the drawer of its height
            b = int(np.argmin([abs(height - hh) for hh in heights]))
            out[first + b].mask = out[first + b].mask | out[j].mask
            out[j].category = ABSORBED
    attached_drawers(seg, out)
    keep = [i for i, p in enumerate(out) if p.category != ABSORBED]
    index = {old: new for new, old in enumerate(keep)}
    for i in keep:
        if out[i].parent is not None:
            out[i].parent = index.get(out[i].parent)
    return [out[i] for i in keep]


def _protrusion(seg: Segments, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, float] | None:
    """(mask, outward axis, front offset) of what stands out beyond the top face's edge, or None."""
    pts = seg.points[mask]
    hgt = seg.height[mask]
    ok = np.all(np.isfinite(pts), axis=1) & np.isfinite(hgt)
    if ok.sum() < TOP_MIN_PIXELS * 2:
        return None
    extent = np.ptp(pts[ok], axis=0)
    if max(extent[0], extent[1]) < HOST_MIN_EXTENT:
        return None
    face = _top_face(seg, mask)
    if face is None:
        return None  # no view of the top: no edge to measure from
    xy, centre, vecs, top = face
    below = ok & (hgt < top - BELOW_TOP)
    best: tuple[int, np.ndarray, float, np.ndarray] | None = None
    for v in (vecs[:, 0], vecs[:, 1]):
        for axis in (v, -v):
            front = float(np.percentile((xy - centre) @ axis, 99.0))
            proj = (pts[:, :2] - centre) @ axis
            out = below & (np.nan_to_num(proj, nan=-1e9) > front + OUT_MARGIN)
            n = int(out.sum())
            if n < OUT_MIN_PIXELS or (best is not None and n <= best[0]):
                continue
            side = np.array([-axis[1], axis[0]])
            span = (xy - centre) @ side  # a drawer slides out within its cabinet's width
            lateral = np.nan_to_num((pts[:, :2] - centre) @ side, nan=1e9)
            out &= (lateral > span.min() - OUT_MARGIN) & (lateral < span.max() + OUT_MARGIN)
            n = int(out.sum())
            if n < OUT_MIN_PIXELS or (best is not None and n <= best[0]):
                continue
            if np.ptp(lateral[out]) < OUT_MIN_WIDTH:
                continue
            best = (n, axis, front, out)
    if best is None:
        return None
    _, axis, front, out = best
    full = np.zeros_like(mask)
    rows, cols = np.nonzero(mask)
    full[rows[out], cols[out]] = True
    if full.sum() > 0.6 * mask.sum():  # most of the segment: not a cabinet with a drawer out
        return None
    return full, axis, front + float(centre @ axis)


def _top_face(seg: Segments, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float] | None:
    """(xy of the top face's points, their centre, their principal axes, top height) of a segment whose
    top is seen, else None."""
    pts, nrm, hgt = seg.points[mask], seg.normals[mask], seg.height[mask]
    ok = np.all(np.isfinite(pts), axis=1) & np.isfinite(hgt)
    if ok.sum() < TOP_MIN_PIXELS:
        return None
    top = float(np.percentile(hgt[ok], 98.0))
    up = np.abs(np.nan_to_num(nrm[:, 2])) > TOP_UP
    top_face = ok & up & (hgt > top - TOP_BAND)
    if top_face.sum() < TOP_MIN_PIXELS:
        return None
    xy = pts[top_face, :2]
    centre = xy.mean(axis=0)
    _, vecs = np.linalg.eigh(np.cov((xy - centre).T))
    return xy, centre, vecs, top


def attached_drawers(seg: Segments, parts: list[Part]) -> None:
    """Segments of their own that are pulled-out drawers of a cabinet in the same view, whatever they were
    recognised as (an open drawer's box looks like a tray or a caddy): a piece hovering in front of the
    cabinet's face (its bottom above the support, ``HOVER`` m at least), within the cabinet's width and
    spanning most of it, below its top, reaching back to its front and standing out of it. Relabelled ``drawer``, parent the cabinet."""
    from scipy.ndimage import binary_dilation

    for k, host in enumerate(parts):
        if host.category != "cabinet":
            continue
        face = _top_face(seg, host.mask)
        if face is None:
            continue
        xy, centre, vecs, top = face
        extent = np.ptp(xy, axis=0)
        if max(extent[0], extent[1]) < HOST_MIN_EXTENT:
            continue
        near = binary_dilation(host.mask, np.ones((3, 3), bool), iterations=2)
        for j, piece in enumerate(parts):
            if j == k or piece.category in ("drawer", "table", "cabinet") or not (piece.mask & near).any():
                continue
            pts, _, _ = _cloud(seg, piece.mask)
            hgt = seg.height[piece.mask]
            hgt = hgt[np.isfinite(hgt)]
            if len(pts) < OUT_MIN_PIXELS or hgt.size == 0 or np.percentile(hgt, 2.0) < HOVER:
                continue
            if np.percentile(hgt, 98.0) > top - BELOW_TOP:
                continue
            size = np.sort(np.percentile(pts, 95.0, axis=0) - np.percentile(pts, 5.0, axis=0))
            if size[-1] <= HANDLE_SIZE and size[0] <= HANDLE_THICK:
                face = _face_behind(seg, parts, j, pts)
                if face is not None and face[0] == k:  # a pull bar standing off the cabinet's face
                    piece.category = "drawer"  # (a handle: split_drawer_fronts gives it its band)
                continue
            for v in (vecs[:, 0], vecs[:, 1]):
                hit = False
                for axis in (v, -v):
                    front = float(np.percentile((xy - centre) @ axis, 99.0))
                    side = np.array([-axis[1], axis[0]])
                    span = (xy - centre) @ side
                    proj = (pts[:, :2] - centre) @ axis
                    lat = (pts[:, :2] - centre) @ side
                    inside = (lat > span.min() - OUT_MARGIN) & (lat < span.max() + OUT_MARGIN)
                    if (
                        inside.mean() >= 0.8
                        and np.percentile(proj, 5.0) <= front + REACH_BACK
                        and np.percentile(proj, 95.0) > front + OUT_MARGIN
                        and np.ptp(lat) >= max(OUT_MIN_WIDTH, DRAWER_WIDTH * np.ptp(span))
                    ):
                        piece.category, piece.parent, hit = "drawer", k, True
                        break
                if hit:
                    break


def _handles_on(
    seg: Segments, parts: list[Part], host: int, drawer: np.ndarray, axis: np.ndarray, front: float
) -> list[tuple[int, float]]:
    """Handle-sized drawer segments in front of the cabinet's front next to the pulled-out region:
    (part index, median height)."""
    from scipy.ndimage import binary_dilation

    near = binary_dilation(drawer, np.ones((3, 3), bool), iterations=3)
    lo, hi = np.nanpercentile(seg.height[drawer], [2.0, 98.0])
    found = []
    for j, part in enumerate(parts):
        if j == host or part.category != "drawer" or not (part.mask & near).any():
            continue
        pts, _, _ = _cloud(seg, part.mask)
        if len(pts) < 3 or np.any(np.ptp(pts, axis=0) > HANDLE_SIZE):
            continue
        height = float(np.nanmedian(seg.height[part.mask]))
        if float(np.median(pts[:, :2] @ axis)) <= front + OUT_MARGIN or not lo <= height <= hi:
            continue  # a closed drawer's handle below or above the pulled-out one
        found.append((j, height))
    return found


def _floor_levels(seg: Segments, mask: np.ndarray) -> list[float]:
    """Heights of the up-facing floors in a pulled-out region (1 cm bins holding at least
    ``FLOOR_SHARE`` of its up-facing pixels, ``FLOOR_GAP`` apart), lowest first."""
    nz = np.abs(np.nan_to_num(seg.normals[..., 2]))
    up = mask & (nz > TOP_UP) & np.isfinite(seg.height)
    h = seg.height[up]
    if h.size < OUT_MIN_PIXELS:
        return []
    bins = np.floor(h / 0.01).astype(np.int64)
    values, counts = np.unique(bins, return_counts=True)
    levels: list[float] = []
    for v, c in sorted(zip(values.tolist(), counts.tolist(), strict=True), key=lambda vc: -vc[1]):
        if c < FLOOR_SHARE * h.size:
            break
        level = float(np.median(h[bins == v]))
        if all(abs(level - x) >= FLOOR_GAP for x in levels):
            levels.append(level)
    return sorted(levels)


def _bands_at(seg: Segments, mask: np.ndarray, cuts: list[float]) -> list[np.ndarray]:
    """The region cut at the given heights into bands, lowest first (bands too small are dropped)."""
    hgt = np.nan_to_num(seg.height, nan=-1e9)
    limits = [-np.inf, *sorted(cuts), np.inf]
    bands = [mask & (hgt >= lo) & (hgt < hi) for lo, hi in pairwise(limits)]
    return [b for b in bands if b.sum() >= OUT_MIN_PIXELS // 2] or [mask]


def _height_bands(seg: Segments, mask: np.ndarray, heights: list[float]) -> list[np.ndarray]:
    """The pulled-out region cut into one band per handle height (limits half-way between them)."""
    if len(heights) < 2:
        return [mask]
    heights = sorted(heights)
    merged = [heights[0]]
    for h in heights[1:]:
        if h - merged[-1] > 0.03:  # two handles of one drawer (or one seen twice) count once
            merged.append(h)
    if len(merged) < 2:
        return [mask]
    return _bands_at(seg, mask, [(a + b) / 2.0 for a, b in pairwise(merged)])
