"""Node errors of the no-oracle detector by kind and category: where node F1 is lost.

Renders the skills-world scenes of ``gsr perceive-eval --no-oracle`` (same scene streams, default views),
perceives them with the detector, pairs perceived and truth nodes by 3D overlap exactly as the
evaluation does (:func:`gsr.perception.match.match_nodes`) and sorts every error:

- ``missed``: a truth node no perceived node is paired with (``hidden`` when no camera shows it);
- ``false``: a perceived node paired with no truth node — ``duplicate`` when its box mostly lies in a
  truth node that is paired with another perceived node (a second copy or a fragment of it), ``fragment``
  when it lies in a truth node that is paired with nothing, ``spurious`` otherwise;
- ``category``: paired, category wrong (truth -> perceived);
- ``colour``: paired, category right, colour wrong.

Rendered scenes are cached (``--cache DIR``) so that detector variants can be compared on the very same
frames. Usage::

    python -m gsr.benchmarks.perception.node_errors --scenes 10 --cameras 4 --seed 5 [--cache /tmp/c] [--json]
        [--no-drawer-completion]
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

import gsr.perception.pipeline as pipeline
import numpy as np
from gsr.benchmarks.perception.eval import skills_scene, visible_nodes
from gsr.perception.detect import load_detector
from gsr.perception.match import NodeScore, match_nodes, node_correct, padded_box, scorable
from gsr.perception.rgbd import View, perceive_rgbd

from gsr.errors import GSRError


def cached_scene(seed: int, cameras: int, cache: Path | None) -> tuple[list[Any], Any, set[str]]:
    """Frames, truth and visible truth ids of one skills scene; pickled under ``cache`` (reused)."""

    path = cache / f"scene_{seed}_{cameras}.pkl" if cache is not None else None
    if path is not None and path.is_file():
        with path.open("rb") as fh:
            return pickle.load(fh)
    frames, truth = skills_scene(seed, cameras, 640, 480, self_filter=True)
    out = (frames, truth, visible_nodes(frames))
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp")
        with tmp.open("wb") as fh:
            pickle.dump(out, fh)
        tmp.replace(path)
    return out


def _inside_share(a: Any, b: Any) -> float:
    """Share of box ``a``'s volume inside box ``b`` (nodes' bboxes, grown by the matcher's pad)."""

    ab, bb = padded_box(a), padded_box(b)
    if ab is None or bb is None:
        return 0.0
    lo, hi = np.maximum(ab[0], bb[0]), np.minimum(ab[1], bb[1])
    inter = float(np.prod(np.clip(hi - lo, 0.0, None)))
    vol = float(np.prod(ab[1] - ab[0]))
    return inter / vol if vol > 0 else 0.0


def classify_errors(graph: Any, truth: Any, visible: set[str]) -> list[dict[str, Any]]:
    """Every node error of one scene as ``{kind, sub, truth, perceived}`` (see the module docstring)."""

    matching = match_nodes(graph, truth)
    tmap = truth.node_map()
    paired_truth = set(matching.values())
    out: list[dict[str, Any]] = []

    def name(n: Any) -> str:
        return f"{n.category}/{n.attributes.get('color', '-')}"

    for t in scorable(truth):
        if t.id not in paired_truth:
            out.append(
                {"kind": "missed", "sub": "hidden" if t.id not in visible else "seen", "truth": name(t)}
            )
    for p in graph.nodes:
        if p.bbox is None:
            continue
        if p.id in matching:
            t = tmap[matching[p.id]]
            if node_correct(p, t):
                continue
            kind = "category" if p.category != t.category else "colour"
            out.append({"kind": kind, "sub": "", "truth": name(t), "perceived": name(p)})
            continue
        best, share = None, 0.0
        for t in scorable(truth):
            s = _inside_share(p, t)
            if s > share:
                best, share = t, s
        if best is not None and share >= 0.5:
            sub = "duplicate" if best.id in paired_truth else "fragment"
            out.append({"kind": "false", "sub": sub, "truth": name(best), "perceived": name(p)})
        else:
            out.append({"kind": "false", "sub": "spurious", "truth": "-", "perceived": name(p)})
    return out


def run(
    scenes: int,
    seed: int,
    cameras: int,
    cache: Path | None,
    detector: Any = None,
    complete_drawers: bool = True,
) -> dict[str, Any]:
    """Perceive the scenes and count errors; ``{nodes, errors, by_kind, by_category, cpu_s}``.

    ``complete_drawers=False`` perceives without the drawer-stack completion
    (:func:`gsr.perception.drawer_slots.hidden_drawers`), for an A/B on the same cached frames."""

    detector = detector or load_detector()
    errors: list[dict[str, Any]] = []
    nodes = NodeScore()
    cpu = 0.0
    kept = pipeline.hidden_drawers
    if not complete_drawers:
        pipeline.hidden_drawers = lambda *args, **kwargs: []
    try:
        graphs = _perceive_all(scenes, seed, cameras, cache, detector)
    finally:
        pipeline.hidden_drawers = kept
    for i, (graph, truth, visible, seconds) in enumerate(graphs):
        cpu += seconds
        nodes.add(graph, truth, match_nodes(graph, truth))
        for e in classify_errors(graph, truth, visible):
            errors.append({**e, "scene": i})
    return _report(nodes, errors, cpu)


def _perceive_all(scenes: int, seed: int, cameras: int, cache: Path | None, detector: Any) -> list[tuple]:
    """(graph, truth, visible ids, perception CPU s) of each scene of the stream."""

    out = []
    for ss in np.random.SeedSequence(seed).spawn(scenes):
        scene_seed = int(ss.generate_state(1)[0])
        frames, truth, visible = cached_scene(scene_seed, cameras, cache)
        c0 = time.process_time()
        graph, _ = perceive_rgbd([View(f.rgb, f.depth, f.camera) for f in frames], detector)
        out.append((graph, truth, visible, time.process_time() - c0))
    return out


def _report(nodes: Any, errors: list[dict[str, Any]], cpu: float) -> dict[str, Any]:
    by_kind = Counter(f"{e['kind']}:{e['sub']}" if e["sub"] else e["kind"] for e in errors)
    by_cat = Counter(
        f"{e['kind']} {e['truth']}" + (f" -> {e['perceived']}" if e["kind"] != "missed" else "")
        for e in errors
    )
    return {
        "nodes": nodes.to_dict(),
        "by_kind": dict(by_kind.most_common()),
        "by_category": dict(by_cat.most_common()),
        "errors": errors,
        "cpu_s": round(cpu, 1),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=10)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--cameras", type=int, default=4)
    ap.add_argument("--cache", type=Path, default=None, help="folder for rendered scenes (reused)")
    ap.add_argument("--model", default=None, help="a `gsr perceive-train` folder (default: shipped)")
    ap.add_argument(
        "--no-drawer-completion",
        action="store_true",
        help="perceive without completing hidden drawers of a stack (A/B on the same cached frames)",
    )
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    try:
        report = run(
            args.scenes,
            args.seed,
            args.cameras,
            args.cache,
            load_detector(args.model),
            complete_drawers=not args.no_drawer_completion,
        )
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps({k: v for k, v in report.items()}, indent=1))
        return 0
    n = report["nodes"]
    print(
        f"nodes P {n['precision']:.3f} R {n['recall']:.3f} F1 {n['f1']:.3f} "
        f"({n['correct']} right of {n['truth']}, {n['predicted']} perceived); CPU {report['cpu_s']} s"
    )
    print("errors by kind: " + ", ".join(f"{k} {v}" for k, v in report["by_kind"].items()))
    for k, v in report["by_category"].items():
        print(f"  {v:3d}  {k}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
