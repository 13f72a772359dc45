"""The no-oracle ``in`` errors one by one, on cached detections: where ``in`` F1 is lost, and A/B of fusion
and relation changes on the very same detector output.

Renders the skills-world scenes of ``gsr perceive-eval --no-oracle`` (same scene streams, default views,
the robot's pixels without depth), runs the detector once per scene and caches its frames (``--cache DIR``;
the detections are keyed by the weights' content, so a retrained model is detected afresh), then perceives
the cached frames (fusion, parts, geometry, relations: :func:`gsr.perception.pipeline.perceive`) and scores
them as the evaluation does: nodes paired by 3D overlap, ``on``/``in`` over all truth relations, and every
``in`` relation classified (:func:`gsr.perception.evaluate.classify_in_errors`) with the perceived
subject's and container's category, colour and box, so an error can be looked at scene by scene.

A development tool: the figures are ``perceive-eval``'s when the detector code and weights are those the
cache was made with (``--redetect`` runs the detector again). Usage::

    python -m gsr.benchmarks.perception.in_errors --seed 5 --scenes 20 --cache /tmp/c [--weights DIR] [--json]
        [--first N]

``--first N`` scores scenes N .. scenes-1 of the stream only (a range of scenes kept apart as a check, or
scenes added to the development set later), the same scenes as a longer run's.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import pickle
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
from gsr.benchmarks.perception.eval import as_truth_ids
from gsr.benchmarks.perception.node_errors import cached_scene
from gsr.perception.detect import SHIPPED_MODEL, load_detector
from gsr.perception.evaluate import ContainmentErrors, Score, classify_in_errors
from gsr.perception.match import NodeScore, match_nodes
from gsr.perception.pipeline import perceive
from gsr.perception.rgbd import View, detect_frames

from gsr.errors import GSRError


def weights_tag(weights: str | Path | None) -> str:
    """A short content hash of the weights folder (``shipped`` folder when none is named)."""
    folder = Path(weights) if weights is not None else SHIPPED_MODEL
    h = hashlib.sha1()
    for name in ("model.npz", "model.json"):
        f = folder / name
        h.update(f.read_bytes() if f.is_file() else b"-")
    return h.hexdigest()[:10]


def _atomic_pickle(path: Path, obj: Any) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    with tmp.open("wb") as fh:
        pickle.dump(obj, fh)
    tmp.replace(path)


def detected_scene(
    scene_seed: int, cameras: int, cache: Path | None, detector: Any, tag: str, redetect: bool = False
) -> tuple[list[Any], Any, set[str], float]:
    """(detected frames, truth, visible truth ids, detector CPU s) of one scene; cached under ``cache``."""
    frames, truth, visible = cached_scene(scene_seed, cameras, cache)
    path = cache / f"det_{scene_seed}_{cameras}_{tag}.pkl" if cache is not None else None
    if path is not None and path.is_file() and not redetect:
        with path.open("rb") as fh:
            detected, cpu = pickle.load(fh)
        return detected, truth, visible, cpu
    c0 = time.process_time()
    detected = detect_frames([View(f.rgb, f.depth, f.camera) for f in frames], detector)
    cpu = time.process_time() - c0
    if path is not None:
        _atomic_pickle(path, (detected, cpu))
    return detected, truth, visible, cpu


def _perceived(name: str, back: dict[str, str], pmap: dict[str, Any]) -> Any:
    """The perceived node behind a truth id (through the pairing) or an ``unmatched_`` id."""
    return pmap.get(back.get(name, name.removeprefix("unmatched_")))


def _describe(node: Any) -> dict[str, Any]:
    if node is None:
        return {}
    box = None
    if node.bbox is not None:
        lo, hi = node.bbox.min, node.bbox.max
        box = [round(float(v), 3) for v in (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z)]
    return {
        "id": node.id,
        "category": node.category,
        "color": node.attributes.get("color"),
        "bbox": box,
        "views": node.attributes.get("views"),
    }


def run(
    scenes: int,
    seed: int,
    cameras: int,
    cache: Path | None,
    weights: str | Path | None = None,
    redetect: bool = False,
    first: int = 0,
) -> dict[str, Any]:
    """Perceive the cached detections of the stream's scenes (from scene ``first`` on); scores and every
    ``in`` relation's class."""
    detector = load_detector(weights)
    tag = weights_tag(weights)
    nodes, score, errors = NodeScore(), Score(), ContainmentErrors()
    rows: list[dict[str, Any]] = []
    det_cpu = fuse_cpu = 0.0
    frames_n = 0
    for i, ss in enumerate(np.random.SeedSequence(seed).spawn(scenes)):
        if i < first:
            continue
        scene_seed = int(ss.generate_state(1)[0])
        detected, truth, visible, cpu = detected_scene(scene_seed, cameras, cache, detector, tag, redetect)
        det_cpu += cpu
        frames_n += len(detected)
        c0 = time.process_time()
        graph = perceive(detected)
        fuse_cpu += time.process_time() - c0
        matching = match_nodes(graph, truth)
        nodes.add(graph, truth, matching)
        renamed = as_truth_ids(graph, matching)
        score.add(renamed, truth, ("on", "in"))
        perceived = set(matching.values())
        errors.add(renamed, truth, visible, perceived)
        back = {t: p for p, t in matching.items()}
        pmap, tmap = graph.node_map(), truth.node_map()

        for kind, a, c, cause in classify_in_errors(renamed, truth, visible, perceived):
            if kind == "tp":
                continue
            truth_a, truth_c = tmap.get(a), tmap.get(c)
            rows.append(
                {
                    "scene": i,
                    "scene_seed": scene_seed,
                    "kind": kind,
                    "cause": cause,
                    "object": a,
                    "container": c,
                    "truth_object": f"{truth_a.category}/{truth_a.attributes.get('color', '-')}"
                    if truth_a
                    else None,
                    "truth_container": f"{truth_c.category}/{truth_c.attributes.get('color', '-')}"
                    if truth_c
                    else None,
                    "perceived_object": _describe(_perceived(a, back, pmap)),
                    "perceived_container": _describe(_perceived(c, back, pmap)),
                }
            )
    rel = score.to_dict()["relations"]
    return {
        "seed": seed,
        "scenes": scenes,
        "first": first,
        "cameras": cameras,
        "weights": tag,
        "nodes": nodes.to_dict(),
        "on": rel["on"],
        "in": rel["in"],
        "in_errors": errors.to_dict(),
        "errors": rows,
        "cpu_ms_per_frame": {
            "detector": round(1000 * det_cpu / max(frames_n, 1), 1),
            "pipeline": round(1000 * fuse_cpu / max(frames_n, 1), 1),
        },
    }


def format_report(report: dict[str, Any]) -> str:
    n, on, inn, err = report["nodes"], report["on"], report["in"], report["in_errors"]
    lines = [
        f"seed {report['seed']}, scenes {report.get('first', 0)}-{report['scenes'] - 1}, {report['cameras']} cameras, "
        f"weights {report['weights']}",
        f"nodes F1 {n['f1']:.3f}  on F1 {on['f1']:.3f}  in P/R/F1 {inn['precision']:.3f}/{inn['recall']:.3f}/"
        f"{inn['f1']:.3f} (tp {inn['tp']} fp {inn['fp']} fn {inn['fn']})  CPU ms/frame detector "
        f"{report['cpu_ms_per_frame']['detector']} pipeline {report['cpu_ms_per_frame']['pipeline']}",
        "missed: " + ", ".join(f"{k} {v}" for k, v in err["missed"].items() if v),
        "false: " + ", ".join(f"{k} {v}" for k, v in err["false"].items() if v),
    ]
    counts = Counter((r["kind"], r["cause"]) for r in report["errors"])
    for r in sorted(
        report["errors"], key=lambda r: (-counts[(r["kind"], r["cause"])], r["kind"], r["cause"])
    ):
        if r["cause"] == "hidden_closed":
            continue
        po, pc = r["perceived_object"], r["perceived_container"]
        lines.append(
            f"  {r['kind']:6s} {r['cause']:24s} #{r['scene']:<3d} {r['object']} ({r['truth_object']}; "
            f"seen {po.get('category')}/{po.get('color')} {po.get('bbox')}) in {r['container']} "
            f"({r['truth_container']}; seen {pc.get('category')}/{pc.get('color')} {pc.get('bbox')})"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=10)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--cameras", type=int, default=4)
    ap.add_argument("--cache", type=Path, default=None, help="folder for rendered scenes and detections")
    ap.add_argument("--weights", default=None, help="a `gsr perceive-train` folder (default: shipped)")
    ap.add_argument("--redetect", action="store_true", help="run the detector again (refresh the cache)")
    ap.add_argument("--first", type=int, default=0, help="score scenes FIRST .. scenes-1 of the stream only")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    try:
        if not 0 <= args.first < args.scenes:
            raise GSRError(
                f"--first {args.first} must lie in 0 .. {args.scenes - 1} (--scenes {args.scenes})"
            )
        report = run(
            args.scenes, args.seed, args.cameras, args.cache, args.weights, args.redetect, args.first
        )
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(json.dumps(report, indent=1) if args.json else format_report(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
