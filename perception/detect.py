"""Instance detection from RGB + depth + camera alone: the no-oracle front end of perception.

Contract (used by the no-oracle pipeline):

- :class:`Detection` — one instance: full-resolution boolean ``mask``, ``category`` (a catalogue category,
  a part such as ``drawer``, ``table`` for the support plane, or ``unknown`` for open-set objects),
  ``score``, ``color`` and ``size`` words and free ``attributes``.
- :class:`Detector` — ``detect(rgb, depth, camera) -> list[Detection]``.
- :func:`load_detector` — the default detector: geometric segmentation (support-plane removal and
  edge-aware clustering, gsr.perception.segment) plus the trained model (object boundaries between
  neighbouring pixels, merging of over-segmented pieces, recognition of category and colour) when its
  weights are found; without weights, geometry
  alone with a shape rule for the category (``attributes["category_source"] == "rule"``).

Weights are the ``gsr perceive-train`` output folder (``model.npz`` + ``model.json`` + ``MODEL_CARD.md``);
inference is numpy only (no torch import at detection time).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from gsr.perception.camera import Camera
from gsr.perception.recognize import (
    FEATURE_NAMES,
    NONE,
    UNKNOWN,
    all_features,
    mask_features,
    pixel_color,
    rule_category,
    size_word,
)
from gsr.perception.recognize_parts import (
    Part,
    cut_dark_handles,
    drop_bare_handles,
    split_drawer_fronts,
    split_open_drawers,
    without_parts,
)
from gsr.perception.segment import LINK_FEATURE_NAMES, SegmentParams, Segments, segment, upsample

from gsr.errors import GSRError

#: Where ``load_detector()`` looks for weights when no path is given: $GSR_PERCEPTION_MODEL, then the
#: weights shipped with the package (trained by ``gsr perceive-train``, see their MODEL_CARD.md).
MODEL_ENV = "GSR_PERCEPTION_MODEL"
SHIPPED_MODEL = Path(__file__).resolve().parent / "model"
MODEL_FILES = ("model.npz", "model.json")
#: Under this colour-head probability the pixel-colour rule names the colour instead.
COLOR_CONFIDENCE = 0.5
#: A piece whose box is under this share of its category's training median volume, lying within the sides
#: and under the top (grown by FRAGMENT_REACH m) of a larger segment of the same category, is part of it.
FRAGMENT_SHARE = 0.05
FRAGMENT_REACH = 0.02


@dataclass(frozen=True)
class Detection:
    """One detected instance in one frame."""

    mask: np.ndarray  # HxW bool, full resolution
    category: str  # catalogue category, part ('drawer'), 'table' (support plane) or 'unknown'
    score: float  # confidence of the category in [0, 1]
    color: str | None = None  # palette word (gsr.categories.COLORS) or None
    size: str | None = None  # 'small' / 'medium' / 'large' or None
    attributes: dict[str, Any] = field(default_factory=dict)
    # attributes always hold "category_source" ('model', 'rule' or 'support_plane'), "pixel_color" (the
    # rule colour of the pixels) and "extent" (major, minor horizontal extent and height, m); a part
    # (a drawer) holds "parent_index": the index of its parent's detection in the same list.


@runtime_checkable
class Detector(Protocol):
    """RGB (HxWx3 uint8), depth (HxW float metres, 0/NaN = no return) and the camera in; detections out."""

    def detect(self, rgb: np.ndarray, depth: np.ndarray, camera: Camera) -> list[Detection]:
        """The instances of one frame."""
        ...


# ------------------------------------------------------------------ the trained model (numpy inference)


class MLP:
    """A ReLU multi-layer perceptron evaluated with numpy; inputs are standardised first."""

    def __init__(self, weights: list[tuple[np.ndarray, np.ndarray]], mean: np.ndarray, std: np.ndarray):
        self.weights = weights
        self.mean = mean
        self.std = std

    def __call__(self, x: np.ndarray) -> np.ndarray:
        h = (np.asarray(x, dtype=np.float64) - self.mean) / self.std
        for k, (w, b) in enumerate(self.weights):
            h = h @ w.T + b
            if k < len(self.weights) - 1:
                h = np.maximum(h, 0.0)
        return h


def softmax(z: np.ndarray) -> np.ndarray:
    """Row-wise softmax."""
    e = np.exp(z - z.max(axis=-1, keepdims=True))
    return e / e.sum(axis=-1, keepdims=True)


@dataclass
class Model:
    """The trained parts: a merge scorer for over-segmented pieces and a category + colour recogniser."""

    merge: MLP
    recognize: MLP
    categories: list[str]
    colors: list[str]  # colour words; 'none' = the catalogue object has no colour word
    unknown_threshold: float
    reference_volume: dict[str, float]
    card: dict[str, Any]
    link: MLP | None = None  # boundary model for neighbouring pixels; None: the segmenter's thresholds

    def link_score(self, feats: np.ndarray) -> np.ndarray:
        """Probability that an object boundary separates each pair of neighbouring pixels."""
        assert self.link is not None
        n = self.link.mean.shape[0]  # the features it was trained on (a prefix of LINK_FEATURE_NAMES)
        return 1.0 / (1.0 + np.exp(-self.link(feats[:, :n])[:, 0]))

    def merge_score(self, feats: np.ndarray) -> np.ndarray:
        """Probability that each adjacent pair of pieces is one object."""
        return 1.0 / (1.0 + np.exp(-self.merge(feats)[:, 0]))

    def classify(self, feats: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Category and colour probabilities, ``(n, categories)`` and ``(n, colors)``."""
        out = self.recognize(feats)
        k = len(self.categories)
        return softmax(out[:, :k]), softmax(out[:, k:])


def _mlp_from(arrays: dict[str, np.ndarray], prefix: str) -> MLP:
    layers = []
    k = 0
    while f"{prefix}.w{k}" in arrays:
        layers.append((arrays[f"{prefix}.w{k}"], arrays[f"{prefix}.b{k}"]))
        k += 1
    if not layers:
        raise GSRError(f"model: no layers named {prefix}.w0 in the weights")
    return MLP(layers, arrays[f"{prefix}.mean"], arrays[f"{prefix}.std"])


def load_model(path: str | Path) -> Model:
    """Read a model folder (model.npz + model.json) written by ``gsr perceive-train``."""
    folder = Path(path)
    if folder.is_file():
        folder = folder.parent
    for name in MODEL_FILES:
        if not (folder / name).is_file():
            raise GSRError(f"{folder}: no {name} (expected the output folder of `gsr perceive-train`)")
    try:
        meta = json.loads((folder / "model.json").read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise GSRError(f"{folder / 'model.json'}: invalid JSON ({exc})") from None
    try:
        with np.load(folder / "model.npz", allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (ValueError, OSError) as exc:
        raise GSRError(f"{folder / 'model.npz'}: not a readable weights file ({exc})") from None
    link_names = meta.get("link_features")
    # a model trained before the last link features were added reads the leading ones only
    if (
        meta.get("features") != list(FEATURE_NAMES)
        or not isinstance(link_names, list)
        or not link_names
        or link_names != list(LINK_FEATURE_NAMES[: len(link_names)])
    ):
        raise GSRError(
            f"{folder}: the model was trained on other features; retrain with `gsr perceive-train`"
        )
    try:
        return Model(
            merge=_mlp_from(arrays, "merge"),
            recognize=_mlp_from(arrays, "recognize"),
            categories=list(meta["categories"]),
            colors=list(meta["colors"]),
            unknown_threshold=float(meta["unknown_threshold"]),
            reference_volume={k: float(v) for k, v in meta.get("reference_volume", {}).items()},
            card=meta,
            link=_mlp_from(arrays, "link"),
        )
    except KeyError as exc:
        raise GSRError(f"{folder / 'model.json'}: missing field {exc}") from None


# ------------------------------------------------------------------ the detector


class RGBDDetector:
    """Geometric segmentation plus (optionally) the trained merge and recognition model."""

    def __init__(self, model: Model | None = None, params: SegmentParams | None = None) -> None:
        self.model = model
        self.params = params or SegmentParams()

    def segments(self, rgb: np.ndarray, depth: np.ndarray, camera: Camera) -> Segments:
        """The merged segmentation of one frame (strided grid)."""
        model = self.model
        seg, _ = segment(
            rgb,
            depth,
            camera,
            self.params,
            merge_scorer=model.merge_score if model is not None else None,
            link_scorer=model.link_score if model is not None and model.link is not None else None,
        )
        return seg

    def detect(self, rgb: np.ndarray, depth: np.ndarray, camera: Camera) -> list[Detection]:
        """Detections of one frame: the support plane (``table``) first, then the objects."""
        seg = self.segments(rgb, depth, camera)
        return detections_from(seg, self.model)


def detections_from(seg: Segments, model: Model | None) -> list[Detection]:
    """Turn a segmentation into detections: recognise each segment, then give drawers their fronts."""
    out: list[Detection] = []
    if seg.plane is not None and seg.support.any():
        out.append(
            Detection(
                mask=seg.full_support(),
                category="table",
                score=1.0,
                attributes={"category_source": "support_plane", "plane": [float(v) for v in seg.plane]},
            )
        )
    if seg.count == 0:
        return out
    feats = all_features(seg)
    parts: list[Part] = []
    if model is None:
        for i in range(seg.count):
            parts.append(Part(seg.labels == i, rule_category(feats[i]), 0.0, pixel_color(feats[i]), i))
    else:
        cat_p, col_p = model.classify(feats)
        for i in range(seg.count):
            k = int(np.argmax(cat_p[i]))
            category, score = model.categories[k], float(cat_p[i, k])
            if category == NONE:
                continue  # not an object (the robot arm, background clutter)
            if score < model.unknown_threshold:
                category = UNKNOWN
            c = model.colors[int(np.argmax(col_p[i]))]
            color = None if c == NONE else c
            if category == UNKNOWN or float(col_p[i].max()) < COLOR_CONFIDENCE:
                color = pixel_color(feats[i])  # open set, or a colour the model is unsure of
            parts.append(Part(seg.labels == i, category, score, color, i))
        parts = split_drawer_fronts(seg, cut_dark_handles(seg, split_open_drawers(seg, parts)))
        parts = drop_bare_handles(seg, parts)
        parts = absorb_fragments(seg, parts, model.reference_volume)
    first = len(out)
    for part in parts:
        f = feats[part.feature_index]
        if model is not None and not np.array_equal(part.mask, seg.labels == part.feature_index):
            f = mask_features(seg, part.mask)  # a part cut out of a segment, or what is left of it
        extent = f[2] * f[3] * max(f[4], 0.005)
        attrs: dict[str, Any] = {
            "pixel_color": pixel_color(f),
            "extent": [round(float(f[2]), 4), round(float(f[3]), 4), round(float(f[4]), 4)],
            "category_source": "rule" if model is None else "model",
        }
        if model is not None:
            attrs["color_score"] = round(float(col_p[part.feature_index].max()), 4)
        if part.parent is not None:
            attrs["parent_index"] = first + part.parent
        ref = model.reference_volume.get(part.category) if model is not None else None
        out.append(
            Detection(
                mask=upsample(part.mask, seg.stride, seg.shape),
                category=part.category,
                score=round(part.score, 4),
                color=part.color,
                size=size_word(float(extent), ref),
                attributes=attrs,
            )
        )
    return out


def _box(seg: Segments, mask: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """(2nd percentile, 98th percentile, min, max) of a mask's points."""
    pts = seg.points[mask]
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) < 3:
        return None
    lo, hi = np.percentile(pts, [2.0, 98.0], axis=0)
    return lo, hi, pts.min(axis=0), pts.max(axis=0)


def absorb_fragments(seg: Segments, parts: list[Part], reference: dict[str, float]) -> list[Part]:
    """Join tiny pieces to the larger segment of the same category whose box holds them.

    A strip of a cabinet's wall seen through a gap (behind a pulled-out drawer) is a segment of its own
    that the recogniser rightly calls ``cabinet``; as a detection it is a second cabinet a few centimetres
    wide that fusion keeps apart. A piece (not a part) whose box volume is under ``FRAGMENT_SHARE`` of
    its category's training median and whose box lies within the sides and under the top of a larger
    same-category segment of the frame, grown by ``FRAGMENT_REACH``, joins that segment."""
    boxes = [_box(seg, p.mask) if p.parent is None else None for p in parts]
    sizes = [int(p.mask.sum()) for p in parts]
    drop: set[int] = set()
    for k, part in enumerate(parts):
        ref = reference.get(part.category)
        box = boxes[k]
        if ref is None or box is None:
            continue
        if float(np.prod(np.maximum(box[1] - box[0], 0.005))) >= FRAGMENT_SHARE * ref:
            continue
        best = None
        for j, other in enumerate(parts):
            ob = boxes[j]
            if j == k or j in drop or ob is None or other.category != part.category or sizes[j] <= sizes[k]:
                continue
            # within its sides and under its top (below its seen part: the rest of it stands on the support)
            inside = np.all(box[0][:2] >= ob[2][:2] - FRAGMENT_REACH) and np.all(
                box[1] <= ob[3] + FRAGMENT_REACH
            )
            if inside and (best is None or sizes[j] > sizes[best]):
                best = j
        if best is not None:
            parts[best].mask = parts[best].mask | part.mask
            drop.add(k)
    return without_parts(parts, drop)


def load_detector(path: str | Path | None = None) -> Detector:
    """The default detector; ``path`` names a ``gsr perceive-train`` output folder.

    Without ``path``: $GSR_PERCEPTION_MODEL, else the shipped weights, else geometry with the shape rule.
    A given path that holds no readable model is an error (never silently the rule)."""
    if path is not None:
        return RGBDDetector(load_model(path))
    env = os.environ.get(MODEL_ENV)
    if env:
        return RGBDDetector(load_model(env))
    if all((SHIPPED_MODEL / n).is_file() for n in MODEL_FILES):
        return RGBDDetector(load_model(SHIPPED_MODEL))
    return RGBDDetector(None)
