"""Scoring a graph whose node ids perception made up: match its nodes to the truth's by 3D overlap.

Without the simulator's ids a perceived ``bowl_1`` has to be paired with the truth's
``akita_black_bowl_1`` before anything can be compared. :func:`match_nodes` pairs them one-to-one by
the overlap of their axis-aligned boxes (each grown by ``PAD``), maximising the total IoU (Hungarian
assignment); a pair needs IoU >= ``MIN_IOU`` or the perceived box's centre inside the truth's box.
Parts are paired with parts and objects with objects. The pairing looks at geometry only; whether the
perceived node is *right* — same category, same colour where the truth names one — is
:func:`node_correct`, which the node precision / recall / F1 of :class:`NodeScore` count.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gsr.categories import normalize_color
from gsr.scene_graph import Node, SceneGraph

#: Boxes grow by this (m) on every side before the overlap test (thin items: a plate, a drawer front).
PAD = 0.01
#: Smallest IoU of the grown boxes for a pair (or the perceived centre inside the truth box).
MIN_IOU = 0.1


def padded_box(n: Node) -> tuple[np.ndarray, np.ndarray] | None:
    """A node's axis-aligned box (min, max) grown by ``PAD`` on every side, as the pairing compares them;
    None without a box."""
    if n.bbox is None:
        return None
    lo, hi = n.bbox.min, n.bbox.max
    return np.array([lo.x, lo.y, lo.z]) - PAD, np.array([hi.x, hi.y, hi.z]) + PAD


_box = padded_box  # the earlier private name; benchmarks/perception/node_errors.py should import padded_box


def box_iou(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> float:
    """IoU of two axis-aligned boxes given as (min, max)."""
    lo, hi = np.maximum(a[0], b[0]), np.minimum(a[1], b[1])
    inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
    va, vb = float(np.prod(a[1] - a[0])), float(np.prod(b[1] - b[0]))
    return inter / (va + vb - inter) if va + vb - inter > 0 else 0.0


def scorable(truth: SceneGraph) -> list[Node]:
    """Truth nodes with a physical body (a pose and a box): map regions and other abstractions are not."""
    return [n for n in truth.nodes if n.pose is not None and n.bbox is not None]


def match_nodes(predicted: SceneGraph, truth: SceneGraph, same_category: float = 0.0) -> dict[str, str]:
    """Perceived node id -> truth node id, one-to-one, by 3D overlap (see the module docstring).

    ``same_category`` is added to the gain of an admissible pair whose categories agree. The evaluation
    pairs by geometry alone (0: a cube read as a book still has its relations scored); a caller that must
    act on what it pairs (the closed loop's body binding) prefers the drawer over the cabinet top that
    overlaps the drawer's body more."""
    from scipy.optimize import linear_sum_assignment

    preds = [(n, b) for n in predicted.nodes if (b := padded_box(n)) is not None]
    trues = [(n, b) for n in scorable(truth) if (b := padded_box(n)) is not None]
    if not preds or not trues:
        return {}
    gain = np.zeros((len(preds), len(trues)))
    for i, (p, pb) in enumerate(preds):
        centre = (pb[0] + pb[1]) / 2
        for j, (t, tb) in enumerate(trues):
            if (p.parent is None) != (t.parent is None):
                continue
            iou = box_iou(pb, tb)
            inside = bool(np.all(centre >= tb[0]) and np.all(centre <= tb[1]))
            if iou >= MIN_IOU or inside:
                gain[i, j] = iou + 1e-3  # any admissible pair beats none
                if p.category == t.category:
                    gain[i, j] += same_category
    rows, cols = linear_sum_assignment(-gain)
    return {preds[r][0].id: trues[c][0].id for r, c in zip(rows, cols, strict=True) if gain[r, c] > 0}


def node_correct(pred: Node, true: Node) -> bool:
    """Same category, and the same colour when the truth names one."""
    if pred.category != true.category:
        return False
    want = true.attributes.get("color")
    if not isinstance(want, str):
        return True
    got = pred.attributes.get("color")
    return isinstance(got, str) and normalize_color(got) == normalize_color(want)


@dataclass
class NodeScore:
    """Node precision / recall / F1 over scenes: a true positive is a matched, correctly named node."""

    truth: int = 0
    predicted: int = 0
    located: int = 0  # matched by overlap, named right or wrong
    correct: int = 0
    unknown: int = 0  # perceived nodes named 'unknown' (open set)
    confusions: dict[str, int] | None = None

    def add(self, predicted: SceneGraph, truth: SceneGraph, matching: dict[str, str]) -> None:
        """Accumulate one scene."""
        if self.confusions is None:
            self.confusions = {}
        tmap, pmap = truth.node_map(), predicted.node_map()
        self.truth += len(scorable(truth))
        self.predicted += sum(1 for n in predicted.nodes if n.bbox is not None)
        self.unknown += sum(1 for n in predicted.nodes if n.category == "unknown")
        self.located += len(matching)
        for p, t in matching.items():
            if node_correct(pmap[p], tmap[t]):
                self.correct += 1
            else:
                key = f"{tmap[t].category}/{tmap[t].attributes.get('color', '-')} -> {pmap[p].category}/{pmap[p].attributes.get('color', '-')}"
                self.confusions[key] = self.confusions.get(key, 0) + 1

    def to_dict(self) -> dict[str, Any]:
        """``{truth, predicted, located, correct, precision, recall, f1, unknown, confusions}``."""
        p = self.correct / self.predicted if self.predicted else 1.0
        r = self.correct / self.truth if self.truth else 1.0
        f1 = 2 * p * r / (p + r) if p + r else 0.0
        top = sorted((self.confusions or {}).items(), key=lambda kv: -kv[1])[:10]
        return {
            "truth": self.truth,
            "predicted": self.predicted,
            "located": self.located,
            "correct": self.correct,
            "precision": round(p, 4),
            "recall": round(r, 4),
            "f1": round(f1, 4),
            "unknown": self.unknown,
            "confusions": dict(top),
        }
