"""Recognition of a segment from its masked RGB-D pixels and point cloud: category, colour, size.

:func:`segment_features` describes every segment of a :class:`~gsr.perception.segment.Segments` with a
fixed-length vector (shape of its point cloud above the support plane, surface orientations, colour
statistics of its masked pixels). A trained :class:`Recognizer` (``gsr.perception.train``) maps the vector
to a category (or ``none``: not an object, e.g. the robot arm) and a colour word; without one,
:func:`rule_category` gives a coarse shape rule, labelled as such. Open set: a model whose best category
probability is below its threshold answers ``unknown`` and keeps the measured attributes.
"""

from __future__ import annotations

import numpy as np
from gsr.perception.geometry import color_name
from gsr.perception.segment import Segments

FEATURE_NAMES = (
    "log_pixels",
    "range",
    "extent_major",
    "extent_minor",
    "height_span",
    "bottom",
    "top",
    "up_share",
    "side_share",
    "below_top_share",
    "top_rough",
    "border_share",
    "chroma_r",
    "chroma_g",
    "chroma_b",
    "brightness",
    "saturation",
    *(f"hue_{k}" for k in range(8)),
    "grey_dark",
    "grey_mid",
    "grey_light",
    "median_r",
    "median_g",
    "median_b",
    "rgb_std",
    "side_fourfold",
)
N_FEATURES = len(FEATURE_NAMES)
#: The answer for a segment that is no object (robot arm, clutter of the background).
NONE = "none"
UNKNOWN = "unknown"


def _hsv(f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mx, mn = f.max(axis=1), f.min(axis=1)
    delta = mx - mn
    sat = np.where(mx > 0, delta / np.maximum(mx, 1e-9), 0.0)
    r, g, b = f[:, 0], f[:, 1], f[:, 2]
    d = np.maximum(delta, 1e-9)
    hue = np.where(mx == r, ((g - b) / d) % 6.0, np.where(mx == g, (b - r) / d + 2.0, (r - g) / d + 4.0)) * (
        np.pi / 3.0
    )
    return hue, sat, mx


def segment_features(seg: Segments, index: int) -> np.ndarray:
    """The feature vector (``FEATURE_NAMES``) of one segment."""
    rows, cols = np.nonzero(seg.labels == index)
    return _features(seg, rows, cols)


def mask_features(seg: Segments, mask: np.ndarray) -> np.ndarray:
    """The feature vector of any strided mask (a segment after a part was cut out of it)."""
    rows, cols = np.nonzero(mask)
    return _features(seg, rows, cols)


#: Shape and colour statistics of a large segment are read from at most this many of its pixels.
MAX_FEATURE_PIXELS = 1500


def _features(seg: Segments, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    pixels = len(rows)
    if pixels > MAX_FEATURE_PIXELS:  # an even subsample (deterministic)
        step = int(np.ceil(pixels / MAX_FEATURE_PIXELS))
        rows, cols = rows[::step], cols[::step]
    pts = seg.points[rows, cols]
    ok = np.all(np.isfinite(pts), axis=1)
    pts = pts[ok]
    hgt = seg.height[rows, cols][ok]
    nrm = np.nan_to_num(seg.normals[rows, cols][ok])
    rgb = seg.rgb[rows, cols][ok].astype(np.float64) / 255.0
    out = np.zeros(N_FEATURES)
    if len(pts) < 3:
        return out
    n = len(pts)
    h, w = seg.labels.shape
    border = np.mean((rows <= 1) | (cols <= 1) | (rows >= h - 2) | (cols >= w - 2))
    xy = pts[:, :2] - pts[:, :2].mean(axis=0)
    cov = xy.T @ xy / n
    _, evecs = np.linalg.eigh(cov)
    proj = xy @ evecs
    lo, hi = np.percentile(proj, [2, 98], axis=0)  # one partition for both ends
    span = hi - lo
    bottom, top = np.percentile(hgt, [2, 98])
    up = np.abs(nrm[:, 2]) > 0.9
    side = np.abs(nrm[:, 2]) < 0.3
    # how box-like the sides are: horizontal normal directions of a box cluster at one angle modulo 90
    # degrees (|mean of exp(4i angle)| near 1), a cylinder's spread evenly (near 0)
    theta = np.arctan2(nrm[side, 1], nrm[side, 0])
    fourfold = float(np.abs(np.exp(4j * theta).mean())) if side.sum() >= 5 else 0.0
    rough = float(np.std(hgt[up])) if up.sum() > 3 else 0.0
    s = rgb.sum(axis=1) + 1e-6
    chroma = (rgb / s[:, None]).mean(axis=0)
    hue, sat, val = _hsv(rgb)
    colored = sat > 0.25
    hist = np.bincount(
        (hue[colored] / (2 * np.pi) * 8).astype(int) % 8, weights=sat[colored], minlength=8
    ) / max(n, 1)
    grey = ~colored
    grey_hist = np.array(
        [
            np.mean(grey & (val < 0.3)),
            np.mean(grey & (val >= 0.3) & (val < 0.7)),
            np.mean(grey & (val >= 0.7)),
        ]
    )
    med = np.median(rgb, axis=0)
    cam = float(np.linalg.norm(pts - seg.camera_position, axis=1).mean())
    out[:] = (
        np.log(pixels * n / len(rows)),
        cam,
        span[1],
        span[0],
        top - bottom,
        bottom,
        top,
        float(up.mean()),
        float(side.mean()),
        float(np.mean(hgt < top - 0.02)),
        rough,
        border,
        *chroma,
        float(val.mean()),
        float(sat.mean()),
        *hist,
        *grey_hist,
        *med,
        float(rgb.std()),
        fourfold,
    )
    return out


def all_features(seg: Segments) -> np.ndarray:
    """Features of every segment, ``(count, N_FEATURES)`` (pixels grouped with one sort)."""
    out = np.zeros((seg.count, N_FEATURES))
    flat = seg.labels.reshape(-1)
    idx = np.flatnonzero(flat >= 0)
    if idx.size == 0:
        return out
    order = idx[np.argsort(flat[idx], kind="stable")]
    ids = flat[order]
    starts = np.searchsorted(ids, np.arange(seg.count))
    ends = np.append(starts[1:], ids.size)
    w = seg.labels.shape[1]
    for i in range(seg.count):
        pix = order[starts[i] : ends[i]]
        out[i] = _features(seg, pix // w, pix % w)
    return out


def rule_category(feat: np.ndarray) -> str:
    """The shape rule used without a trained model (coarse; documented as such)."""
    return shape_category(float(feat[2]), float(feat[3]), float(feat[4]))


def shape_category(major: float, minor: float, height: float) -> str:
    """The coarse shape rule on an object's major and minor horizontal extent and height (m)."""
    if height > 0.25 or major > 0.35:
        return "cabinet" if height > 0.2 and major < 0.8 else UNKNOWN
    if height < 0.035 and major > 0.1:
        return "plate"
    if height > 1.8 * major and height > 0.08:
        return "bottle"
    if max(major, minor, height) < 0.07 and min(minor, height) > 0.02:
        return "cube"
    return UNKNOWN


def pixel_color(feat: np.ndarray) -> str:
    """The palette word of a segment's median pixel colour (hue / saturation / value rule)."""
    med = np.clip(feat[FEATURE_NAMES.index("median_r") : FEATURE_NAMES.index("median_b") + 1], 0, 1)
    return color_name((med * 255.0).reshape(1, 3))


def size_word(volume: float, reference: float | None) -> str:
    """small / medium / large: relative to the category's typical volume when known, else absolute."""
    if reference and reference > 0:
        r = volume / reference
        return "small" if r < 0.6 else ("large" if r > 1.6 else "medium")
    return "small" if volume < 2e-4 else ("large" if volume > 5e-3 else "medium")
