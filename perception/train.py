"""Training of the no-oracle detector's learned parts from labelled frames, and its held-out evaluation.

Three small models (torch on the CPU, exported as numpy arrays for :mod:`gsr.perception.detect`):

- **link** — an MLP over the local features of two neighbouring pixels
  (:data:`gsr.perception.segment.LINK_FEATURE_NAMES`: depth step, unexplained jump, normals, colour) that
  says whether an object boundary separates them; it replaces the segmenter's fixed thresholds.

- **merge** — an MLP over the features of two adjacent pieces of the geometric over-segmentation
  (:data:`gsr.perception.segment.PAIR_FEATURE_NAMES`) that says whether they are one object. It decides
  what geometry cannot: pieces of one object split by shading or a handle, versus two objects that touch
  with continuous depth (a mug on a box, a drawer and its cabinet).
- **recognize** — an MLP over a segment's features (:data:`gsr.perception.recognize.FEATURE_NAMES`:
  point-cloud shape above the support plane, surface orientations, colour statistics of its masked
  pixels) with two heads: the category (catalogue categories and parts, plus ``none`` for what is no
  object, such as the robot arm) and the colour word (plus ``none``: the object's name has no colour).

The frames come from the caller (the perception layer renders nothing): ``gsr perceive-train`` feeds
frames rendered by gsr.benchmarks.perception.train_data. Labels (``Frame.masks``/``Frame.labels``) are
read only here and in :func:`evaluate`, never by the detector.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from gsr.perception.detect import MLP, Model, RGBDDetector, detections_from, load_model
from gsr.perception.frame import Frame
from gsr.perception.recognize import FEATURE_NAMES, NONE, all_features
from gsr.perception.segment import (
    LINK_FEATURE_NAMES,
    PAIR_FEATURE_NAMES,
    SegmentParams,
    Segments,
    plain_links,
    segment,
)

from gsr.errors import GSRError
from gsr.io import write_text_atomic

#: A boundary link is subtle (over-sampled in training) below this unexplained step / depth and this
#: chromaticity change.
SUBTLE_JUMP = 0.03
SUBTLE_CHROMA = 0.05
#: Truth objects smaller than this many strided pixels are not counted in the evaluation.
MIN_TRUTH_PIXELS = 25


@dataclass(frozen=True)
class TrainConfig:
    """Sizes of the data and the models (defaults: the shipped model's recipe)."""

    link_frames: int = 150  # the first frames train the link (boundary) model
    merge_frames: int = 240  # the next ones the merge model, the rest recognition
    link_samples: int = 3000  # links sampled per frame (a quarter of them boundaries, when there are)
    link_epochs: int = 250
    epochs: int = 600
    hidden: int = 96
    merge_hidden: int = 32
    lr: float = 3e-3
    weight_decay: float = 1e-4
    validation_share: float = 0.15  # of the recognition samples: picks the open-set threshold
    unknown_quantile: float = 0.03  # threshold = this quantile of the validation's correct confidences
    threads: int = 1
    seed: int = 0
    params: SegmentParams = field(default_factory=SegmentParams)


# ------------------------------------------------------------------ labels of segments


def _strided_truth(frame: Frame, stride: int) -> np.ndarray:
    return np.asarray(frame.masks)[::stride, ::stride]


def majority(labels: np.ndarray, truth: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Per segment: the truth mask id covering most of its pixels (-1 = none) and that share."""
    m = labels >= 0
    seg_ids = labels[m].astype(np.int64)
    t = truth[m].astype(np.int64)
    if count == 0:
        return np.zeros(0, np.int64), np.zeros(0)
    uniq_t, t_idx = np.unique(t, return_inverse=True)
    key = seg_ids * len(uniq_t) + t_idx
    counts = np.bincount(key, minlength=count * len(uniq_t)).reshape(count, len(uniq_t))
    best = counts.argmax(axis=1)
    total = counts.sum(axis=1)
    share = counts[np.arange(count), best] / np.maximum(total, 1)
    return uniq_t[best], share


def target_of(frame: Frame, mask_id: int) -> tuple[str, str]:
    """(category, colour) a segment should be recognised as: ``none`` for no object or the table."""
    label = frame.labels.get(int(mask_id))
    if label is None or label.ignore or label.keypoint_of is not None or label.category in ("table", "floor"):
        return NONE, NONE
    return label.category, (label.color or NONE)


# ------------------------------------------------------------------ sample collection


@dataclass
class Samples:
    """Training rows gathered from frames."""

    pair_x: list[np.ndarray] = field(default_factory=list)
    pair_y: list[np.ndarray] = field(default_factory=list)
    seg_x: list[np.ndarray] = field(default_factory=list)
    seg_cat: list[str] = field(default_factory=list)
    seg_col: list[str] = field(default_factory=list)
    frames: int = 0
    seconds: float = 0.0


def add_links(
    xs: list[np.ndarray], ys: list[np.ndarray], frame: Frame, config: TrainConfig, rng: np.random.Generator
) -> None:
    """Sample a frame's pixel links: features and whether two different truth instances meet there."""
    found: list = []
    seg, _ = segment(frame.rgb, frame.depth, frame.camera, config.params, merge=False, link_samples=found)
    truth = _strided_truth(frame, seg.stride)
    if len(found) != 2:
        return
    (fr, br), (fd, bd) = found
    cut = np.concatenate(((truth[:, :-1] != truth[:, 1:])[br], (truth[:-1, :] != truth[1:, :])[bd]))
    feats = np.concatenate((fr, fd))
    asked = ~plain_links(feats)  # the detector keeps plain links without the model: train on the rest
    pos, neg = np.flatnonzero(cut & asked), np.flatnonzero(~cut & asked)
    # half of the boundary samples are subtle ones (a small unexplained step, no colour change: an open
    # drawer beside its cabinet's side), which uniform sampling would leave to a handful
    subtle = (feats[pos, 1] < SUBTLE_JUMP) & (feats[pos, 4] < SUBTLE_CHROMA)
    k = config.link_samples // 4
    hard = rng.choice(pos[subtle], min(k // 2, int(subtle.sum())), replace=False)
    rest = np.setdiff1d(pos, hard)
    take = np.concatenate(
        (
            hard,
            rng.choice(rest, min(k - len(hard), len(rest)), replace=False),
            rng.choice(neg, min(config.link_samples - k, len(neg)), replace=False),
        )
    )
    xs.append(feats[take])
    ys.append(cut[take].astype(np.float32))


def _train_link(
    xs: list[np.ndarray], ys: list[np.ndarray], config: TrainConfig, log: Callable[[str], None]
) -> MLP:
    x, y = np.concatenate(xs), np.concatenate(ys)
    log(f"link: {len(y)} pixel links, {float(y.mean()):.3f} of them boundaries")
    layers, mean, std = _fit(x, [y], [1], 16, replace(config, epochs=config.link_epochs), binary=True)
    return MLP(layers, mean, std)


def add_pairs(
    samples: Samples, frame: Frame, params: SegmentParams, link_scorer: Callable | None = None
) -> None:
    """Over-segment a frame and record each adjacent pair's features and whether it is one object."""
    seg, (pairs, feats) = segment(
        frame.rgb, frame.depth, frame.camera, params, merge=False, link_scorer=link_scorer
    )
    if len(pairs) == 0:
        return
    major, _ = majority(seg.labels, _strided_truth(frame, seg.stride), seg.count)
    samples.pair_x.append(feats)
    samples.pair_y.append((major[pairs[:, 0]] == major[pairs[:, 1]]).astype(np.float32))


def add_segments(samples: Samples, frame: Frame, seg: Segments) -> None:
    """Record the features and targets of every segment of a (merged) segmentation."""
    if seg.count == 0:
        return
    major, _ = majority(seg.labels, _strided_truth(frame, seg.stride), seg.count)
    samples.seg_x.append(all_features(seg))
    for mask_id in major.tolist():
        cat, col = target_of(frame, mask_id)
        samples.seg_cat.append(cat)
        samples.seg_col.append(col)


# ------------------------------------------------------------------ torch training


def _fit(
    x: np.ndarray,
    targets: list[np.ndarray],
    sizes: list[int],
    hidden: int,
    config: TrainConfig,
    binary: bool = False,
) -> tuple[list[tuple[np.ndarray, np.ndarray]], np.ndarray, np.ndarray]:
    """Train an MLP (2 hidden layers) with one or more softmax heads (or one logistic output)."""
    import torch

    torch.set_num_threads(config.threads)
    torch.manual_seed(config.seed)
    mean = x.mean(axis=0)
    std = x.std(axis=0) + 1e-6
    xt = torch.tensor((x - mean) / std, dtype=torch.float32)
    out_dim = 1 if binary else sum(sizes)
    net = torch.nn.Sequential(
        torch.nn.Linear(x.shape[1], hidden),
        torch.nn.ReLU(),
        torch.nn.Linear(hidden, hidden),
        torch.nn.ReLU(),
        torch.nn.Linear(hidden, out_dim),
    )
    opt = torch.optim.AdamW(net.parameters(), lr=config.lr, weight_decay=config.weight_decay)
    ys = [torch.tensor(t) for t in targets]
    for _epoch in range(config.epochs):
        opt.zero_grad()
        out = net(xt)
        if binary:
            loss = torch.nn.functional.binary_cross_entropy_with_logits(out[:, 0], ys[0].float())
        else:
            loss = torch.zeros(())
            start = 0
            for size, y in zip(sizes, ys, strict=True):
                logits = out[:, start : start + size]
                keep = y >= 0
                if keep.any():
                    loss = loss + torch.nn.functional.cross_entropy(logits[keep], y[keep])
                start += size
        loss.backward()
        opt.step()
    layers = [
        (m.weight.detach().numpy().astype(np.float64), m.bias.detach().numpy().astype(np.float64))
        for m in net
        if isinstance(m, torch.nn.Linear)
    ]
    return layers, mean, std


def _arrays(prefix: str, mlp: MLP) -> dict[str, np.ndarray]:
    out = {f"{prefix}.mean": mlp.mean, f"{prefix}.std": mlp.std}
    for k, (w, b) in enumerate(mlp.weights):
        out[f"{prefix}.w{k}"] = w
        out[f"{prefix}.b{k}"] = b
    return out


def train(
    frames: Iterable[Frame],
    config: TrainConfig | None = None,
    log: Callable[[str], None] | None = None,
    data_note: str = "",
) -> Model:
    """Train the merge and recognition models on labelled frames (an iterable, consumed once)."""
    config = config or TrainConfig()
    log = log or (lambda _m: None)
    start_cpu, start = time.process_time(), time.perf_counter()
    merge_samples, seg_samples = Samples(), Samples()
    link_x: list[np.ndarray] = []
    link_y: list[np.ndarray] = []
    link_model: MLP | None = None
    merge_model: MLP | None = None
    rng = np.random.default_rng(config.seed)
    n = 0
    for frame in frames:
        n += 1
        if n <= config.link_frames:
            add_links(link_x, link_y, frame, config, rng)
            continue
        if link_model is None:
            if not link_y:
                raise GSRError("perceive-train: the frames gave no pixel links (empty scenes?)")
            link_model = _train_link(link_x, link_y, config, log)
        if n <= config.link_frames + config.merge_frames:
            add_pairs(merge_samples, frame, config.params, _scorer(link_model))
            if n % 50 == 0:
                log(f"frames {n}: {sum(len(y) for y in merge_samples.pair_y)} pairs")
            continue
        if merge_model is None:
            if not merge_samples.pair_y:
                raise GSRError("perceive-train: the frames gave no training pairs (empty scenes?)")
            merge_model = _train_merge(merge_samples, config, log)
        seg, _ = segment(  # as the detector segments: the link model's boundaries, the merge model
            frame.rgb,
            frame.depth,
            frame.camera,
            config.params,
            merge_scorer=_scorer(merge_model),
            link_scorer=_scorer(link_model),
        )
        add_segments(seg_samples, frame, seg)
        if n % 50 == 0:
            log(f"frames {n}: {len(seg_samples.seg_cat)} segments")
    if merge_model is None:
        raise GSRError(
            f"perceive-train: all {n} frames went to the link and merge models (link_frames="
            f"{config.link_frames}, merge_frames={config.merge_frames}); "
            "give more frames for recognition"
        )
    if len(seg_samples.seg_cat) < 10:
        raise GSRError("perceive-train: too few segments to train recognition")
    x = np.concatenate(seg_samples.seg_x)
    categories = sorted(set(seg_samples.seg_cat))
    colors = sorted(set(seg_samples.seg_col))
    y_cat = np.array([categories.index(c) for c in seg_samples.seg_cat])
    y_col = np.array([colors.index(c) for c in seg_samples.seg_col])
    # a colour answer only matters for objects: 'none'-category rows do not train the colour head
    y_col_train = np.where(np.array(seg_samples.seg_cat) == NONE, -1, y_col)
    rng = np.random.default_rng(config.seed)
    val = rng.random(len(x)) < config.validation_share
    log(f"recognition: {len(x)} segments ({int(val.sum())} validation), {len(categories)} categories")
    layers, mean, std = _fit(
        x[~val], [y_cat[~val], y_col_train[~val]], [len(categories), len(colors)], config.hidden, config
    )
    recog = MLP(layers, mean, std)
    probe = Model(merge_model, recog, categories, colors, 0.0, {}, {}, link_model)
    p_cat, p_col = probe.classify(x[val])
    pred = p_cat.argmax(axis=1)
    correct = pred == y_cat[val]
    conf = p_cat.max(axis=1)
    threshold = float(np.quantile(conf[correct], config.unknown_quantile)) if correct.any() else 0.5
    threshold = min(threshold, 0.5)
    obj = y_cat[val] != categories.index(NONE) if NONE in categories else np.ones(int(val.sum()), bool)
    col_ok = p_col.argmax(axis=1) == y_col[val]
    ref: dict[str, float] = {}
    vol = x[:, 2] * x[:, 3] * np.maximum(x[:, 4], 0.005)
    for k, c in enumerate(categories):
        if (y_cat == k).any():
            ref[c] = float(np.median(vol[y_cat == k]))
    counts = {c: int((y_cat == k).sum()) for k, c in enumerate(categories)}
    card = {
        "features": list(FEATURE_NAMES),
        "pair_features": list(PAIR_FEATURE_NAMES),
        "link_features": list(LINK_FEATURE_NAMES),
        "categories": categories,
        "colors": colors,
        "unknown_threshold": round(threshold, 4),
        "reference_volume": ref,
        "training": {
            "frames": n,
            "link_frames": config.link_frames,
            "link_samples": int(sum(len(y) for y in link_y)),
            "merge_frames": config.merge_frames,
            "pairs": int(sum(len(y) for y in merge_samples.pair_y)),
            "segments": len(x),
            "segments_per_category": counts,
            "epochs": config.epochs,
            "hidden": config.hidden,
            "seed": config.seed,
            "threads": config.threads,
            "cpu_seconds": round(time.process_time() - start_cpu, 1),
            "wall_seconds": round(time.perf_counter() - start, 1),
            "data": data_note,
        },
        "validation": {
            "segments": int(val.sum()),
            "category_accuracy": round(float(correct.mean()), 4) if val.any() else None,
            "color_accuracy_objects": round(float(col_ok[obj].mean()), 4) if obj.any() else None,
        },
    }
    log(f"validation: category accuracy {card['validation']['category_accuracy']}, threshold {threshold:.3f}")
    return Model(merge_model, recog, categories, colors, threshold, ref, card, link_model)


def _scorer(mlp: MLP) -> Callable[[np.ndarray], np.ndarray]:
    return lambda f: 1.0 / (1.0 + np.exp(-mlp(f)[:, 0]))


def _train_merge(samples: Samples, config: TrainConfig, log: Callable[[str], None]) -> MLP:
    x = np.concatenate(samples.pair_x)
    y = np.concatenate(samples.pair_y)
    log(f"merge: {len(y)} pairs, {float(y.mean()):.3f} of them one object")
    layers, mean, std = _fit(x, [y], [1], config.merge_hidden, config, binary=True)
    return MLP(layers, mean, std)


# ------------------------------------------------------------------ saving


def save_model(model: Model, out: str | Path, heldout: dict[str, Any] | None = None) -> Path:
    """Write model.npz, model.json and MODEL_CARD.md into ``out``, each atomically (temp file + rename)."""
    folder = Path(out)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GSRError(f"{folder}: cannot create the output folder ({exc.strerror})") from None
    arrays = {**_arrays("merge", model.merge), **_arrays("recognize", model.recognize)}
    if model.link is not None:
        arrays.update(_arrays("link", model.link))
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=".npz.tmp")
    os.close(fd)
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
        os.chmod(tmp, 0o644)  # mkstemp makes private files; weights are meant to be shared
        os.replace(tmp, folder / "model.npz")
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    meta = dict(model.card)
    if heldout is not None:
        meta["heldout"] = heldout
    write_text_atomic(folder / "model.json", json.dumps(meta, indent=1) + "\n")
    write_text_atomic(folder / "MODEL_CARD.md", model_card(meta))
    load_model(folder)  # what was written reads back
    return folder


def model_card(meta: dict[str, Any]) -> str:
    """The model card (Markdown) from the model's metadata."""
    tr = meta["training"]
    lines = [
        "# No-oracle detector: link, merge and recognition models",
        "",
        "Trained by `gsr perceive-train` (gsr.perception.train) on the CPU; inference is numpy "
        "(gsr.perception.detect). No downloaded weights or data.",
        "",
        "## Training data",
        "",
        tr.get("data") or "(frames given by the caller)",
        "",
        f"- frames: {tr['frames']} (the first {tr['link_frames']} for the link model, the next "
        f"{tr['merge_frames']} for the merge model, the rest for recognition)",
        f"- pixel links: {tr['link_samples']}; adjacent piece pairs: {tr['pairs']}; segments: {tr['segments']}",
        f"- MLPs: link {len(LINK_FEATURE_NAMES)}-16-16-1, merge {len(PAIR_FEATURE_NAMES)}-32-32-1, recognition {len(FEATURE_NAMES)}-"
        f"{tr['hidden']}-{tr['hidden']}-({len(meta['categories'])} categories + {len(meta['colors'])} colours); "
        f"{tr['epochs']} full-batch AdamW epochs, seed {tr['seed']}",
        f"- cost: {tr['cpu_seconds']} CPU-s, {tr['wall_seconds']} s wall ({tr['threads']} torch thread(s))",
        "",
        "Segments per category: "
        + ", ".join(
            f"{c} {k}" for c, k in sorted(tr["segments_per_category"].items(), key=lambda kv: -kv[1])
        ),
        "",
        "## Measured accuracy",
        "",
        f"Validation (segments of the training scenes kept out of training): category accuracy "
        f"{meta['validation']['category_accuracy']}, colour accuracy over objects "
        f"{meta['validation']['color_accuracy_objects']}. Open-set threshold (max category probability "
        f"under which the answer is `unknown`): {meta['unknown_threshold']}.",
        "",
    ]
    held = meta.get("heldout")
    if held:
        lines += [f"Held-out scenes (seeds never used in training): {held.get('note', '')}", ""]
        lines += ["| detector | instance recall | instance precision | category acc. | colour acc. |"]
        lines += ["|---|---:|---:|---:|---:|"]
        for name, r in held.get("results", {}).items():
            lines.append(
                f"| {name} | {r['recall']} | {r['precision']} | {r['category_accuracy']} | "
                f"{r['color_accuracy']} |"
            )
        lines.append("")
        lines.append(
            "Instance recall: truth objects (>= "
            f"{MIN_TRUTH_PIXELS} strided pixels) matched by a detection with mask IoU >= 0.5; precision: "
            "detections (not the table) matched to a truth object; accuracies over matched objects."
        )
        lines.append("")
    lines += [
        "## Where it will not generalise",
        "",
        "- Real cameras: trained only on PyBullet's TinyRenderer images (flat shading, no texture, no "
        "specular highlights, no motion blur) and depth with Gaussian noise only (no missing returns at "
        "edges, no multipath). Expect lower accuracy on a real RGB-D sensor without retraining.",
        "- Unseen object kinds: categories are those of the project's asset library listed above; other "
        "objects are reported `unknown` only when the model is unsure, and can be forced into a known "
        "class with a similar shape and colour.",
        "- Colour words: the colour head knows only the words of the training objects ("
        + ", ".join(c for c in meta["colors"] if c != NONE)
        + "); when it is unsure (probability < 0.5) the detector reports the pixel-colour rule's word. "
        "Textured or multi-coloured objects get their dominant colour.",
        "- Gravity must be world -z (the camera pose is needed): the support plane is the largest "
        "horizontal surface.",
        "- Parts that show no geometric or colour boundary stay in their parent's segment: a lid of the "
        "box's colour; an open drawer whose side is inset by a centimetre from its cabinet's side when no "
        "view shows the cabinet's top (with the top in view the detector cuts out what stands beyond the "
        "top's edge, a geometric rule outside these weights); closed drawers are found only through their "
        "visible handles.",
        "",
    ]
    return "\n".join(lines)


# ------------------------------------------------------------------ held-out evaluation


def evaluate(frames: Iterable[Frame], detectors: dict[str, RGBDDetector]) -> dict[str, dict[str, Any]]:
    """Instance recall/precision and category/colour accuracy of each detector on the same labelled frames."""
    tallies = {
        name: dict.fromkeys(("truth", "matched", "dets", "cat_ok", "col_ok", "col_n"), 0)
        for name in detectors
    }
    frames_n = 0
    for frame in frames:
        frames_n += 1
        for name, detector in detectors.items():
            _score_frame(frame, detector, tallies[name])
    out = {}
    for name, t in tallies.items():
        out[name] = {
            "frames": frames_n,
            "truth_objects": t["truth"],
            "detections": t["dets"],
            "recall": round(t["matched"] / t["truth"], 4) if t["truth"] else None,
            "precision": round(t["matched"] / t["dets"], 4) if t["dets"] else None,
            "category_accuracy": round(t["cat_ok"] / t["matched"], 4) if t["matched"] else None,
            "color_accuracy": round(t["col_ok"] / t["col_n"], 4) if t["col_n"] else None,
        }
    return out


def _score_frame(frame: Frame, detector: RGBDDetector, t: dict[str, int]) -> None:
    """Match one frame's detections to its truth objects (mask IoU >= 0.5, greedy) and tally."""
    seg = detector.segments(frame.rgb, frame.depth, frame.camera)
    dets = _segment_detections(seg, detector)
    truth = _strided_truth(frame, seg.stride)
    ids, counts = np.unique(truth[truth >= 0], return_counts=True)
    objects = {
        int(i): truth == i
        for i, c in zip(ids.tolist(), counts.tolist(), strict=True)
        if c >= MIN_TRUTH_PIXELS and target_of(frame, i)[0] != NONE
    }
    t["truth"] += len(objects)
    t["dets"] += len(dets)
    used: set[int] = set()
    for mask, category, color in dets:
        best, best_iou = None, 0.5
        for i, obj in objects.items():
            if i in used:
                continue
            inter = int((mask & obj).sum())
            if inter == 0:
                continue
            iou = inter / int((mask | obj).sum())
            if iou >= best_iou:
                best, best_iou = i, iou
        if best is None:
            continue
        used.add(best)
        t["matched"] += 1
        cat, col = target_of(frame, best)
        t["cat_ok"] += int(category == cat)
        if col != NONE:
            t["col_n"] += 1
            t["col_ok"] += int(color == col)


def _segment_detections(seg: Segments, detector: RGBDDetector) -> list[tuple[np.ndarray, str, str | None]]:
    """(strided mask, category, colour) of each non-table detection, as the detector reports them."""
    out = []
    for d in detections_from(seg, detector.model):
        if d.category == "table":
            continue
        out.append((d.mask[:: seg.stride, :: seg.stride], d.category, d.color))
    return out
