"""Articulated parts that show no boundary of their own: closed drawers found from their handles.

A closed drawer's front is flush with its cabinet's front and (in the asset library) nearly the same
colour, so no depth or colour edge separates it; its pull handle, standing off the front, does. The
recogniser labels a handle-sized segment ``drawer``; :func:`split_drawer_fronts` finds the vertical face
behind each such handle (2-8 cm behind it, on another segment: the host), cuts that face into horizontal
bands (one per handle, limits half-way between neighbouring handles' heights) and gives each band to its
drawer. Every drawer (banded or a segment of its own, e.g. an open one) gets a parent: the host of its face, or
the non-drawer segment whose box lies nearest (within ``HOST_REACH``).
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


def split_drawer_fronts(seg: Segments, parts: list[Part]) -> list[Part]:
    """Give closed drawers their front bands and every drawer a parent (see the module docstring)."""
    hosts: dict[int, list[tuple[int, float, np.ndarray, np.ndarray]]] = {}
    for k, part in enumerate(parts):
        if part.category != "drawer":
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
