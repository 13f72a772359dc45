"""Perception speed and accuracy: frames/s of ``perceive`` alone, and F1 against depth noise / mask erosion.

Run: ``python benchmarks/bench_perception.py [--frames 30] [--scenes 30] [--seed 0] [--json]``
(``--only fps`` or ``--only noise`` for one part; ``--only detect [--weights DIR]`` times the no-oracle
detector: segmentation, detection and the whole no-oracle pipeline per frame over 4-camera scenes;
``--only openset --scenes 6`` shows what it calls the procedural world's primitives, assets it never saw). Frames are 640x480 renders of random scenes (both
worlds, see benchmarks/perception/eval.py); they are rendered first, then each is perceived
``--repeats`` times and the median time per frame is kept, so rendering never enters the timing. The
machine's load average is printed with the figures because the development machine is shared.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np
from gsr.benchmarks.perception.eval import evaluate, procedural_scene, skills_scene
from gsr.perception.detect import load_detector
from gsr.perception.pipeline import perceive
from gsr.perception.rgbd import View, perceive_rgbd
from gsr.perception.train import MIN_TRUTH_PIXELS, target_of

NOISE = (0.0, 0.002, 0.005, 0.01, 0.02)
EROSION = (0, 2, 4)


def bench_fps(frames: int, seed: int, repeats: int, world: str) -> dict[str, Any]:
    """Median seconds per 640x480 frame of ``perceive`` over ``frames`` rendered scenes."""
    make = procedural_scene if world == "procedural" else skills_scene
    seeds = [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(frames)]
    rendered = [make(s, 1, 640, 480)[0][0] for s in seeds]
    perceive(rendered[0])  # one-off imports (open3d) are not a per-frame cost
    load_before = os.getloadavg()[0]
    per_frame, cpu_per_frame = [], []
    for frame in rendered:
        times, cpu = [], []
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            perceive(frame)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
        per_frame.append(statistics.median(times))
        cpu_per_frame.append(statistics.median(cpu))
    mean = sum(per_frame) / len(per_frame)
    cpu_mean = sum(cpu_per_frame) / len(cpu_per_frame)
    return {
        "world": world,
        "frames": frames,
        "resolution": [640, 480],
        "ms_per_frame_mean": round(1000 * mean, 1),
        "ms_per_frame_p90": round(1000 * float(np.percentile(per_frame, 90)), 1),
        "fps": round(1.0 / mean, 1),
        # CPU seconds of this process (all its threads): what a frame costs without other users' load
        "cpu_ms_per_frame_mean": round(1000 * cpu_mean, 1),
        "fps_cpu": round(1.0 / cpu_mean, 1),
        "load_average": [round(load_before, 2), round(os.getloadavg()[0], 2)],
        "cpus": os.cpu_count(),
    }


def bench_detect(scenes: int, seed: int, repeats: int, weights: str | None = None) -> dict[str, Any]:
    """The no-oracle detector (gsr.perception.detect) per 640x480 frame: segmentation alone, detection
    (segmentation + recognition) and the whole no-oracle pipeline (detection + fusion + relations) over the
    4 default views of ``scenes`` skills-world scenes. Median of ``repeats`` per frame, then the mean."""

    detector = load_detector(weights)
    seeds = [int(s.generate_state(1)[0]) for s in np.random.SeedSequence([seed, 5]).spawn(scenes)]
    scenes_frames = [skills_scene(s, 4, 640, 480)[0] for s in seeds]
    f0 = scenes_frames[0][0]
    detector.detect(f0.rgb, f0.depth, f0.camera)  # one-off imports
    load_before = os.getloadavg()[0]

    def timed(fn) -> tuple[float, float]:
        walls, cpus = [], []
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            fn()
            walls.append(time.perf_counter() - start)
            cpus.append(time.process_time() - start_cpu)
        return statistics.median(walls), statistics.median(cpus)

    seg_t, det_t, pipe_t = [], [], []
    for frames in scenes_frames:
        for f in frames:
            seg_t.append(timed(lambda f=f: detector.segments(f.rgb, f.depth, f.camera)))
            det_t.append(timed(lambda f=f: detector.detect(f.rgb, f.depth, f.camera)))
        views = [View(rgb=f.rgb, depth=f.depth, camera=f.camera) for f in frames]
        wall, cpu = timed(lambda views=views: perceive_rgbd(views, detector))
        pipe_t.append((wall / len(frames), cpu / len(frames)))

    def row(ts: list[tuple[float, float]]) -> dict[str, float]:
        wall = sum(t[0] for t in ts) / len(ts)
        cpu = sum(t[1] for t in ts) / len(ts)
        return {
            "ms_wall": round(1000 * wall, 1),
            "ms_cpu": round(1000 * cpu, 1),
            "fps": round(1 / wall, 1),
            "fps_cpu": round(1 / cpu, 1),
        }

    return {
        "frames": sum(len(f) for f in scenes_frames),
        "model": "trained" if getattr(detector, "model", None) is not None else "rules (no weights)",
        "segmentation": row(seg_t),
        "detection": row(det_t),
        "pipeline_4_views_per_frame": row(pipe_t),
        "load_average": [round(load_before, 2), round(os.getloadavg()[0], 2)],
        "cpus": os.cpu_count(),
    }


def bench_openset(scenes: int, seed: int, weights: str | None = None) -> dict[str, dict[str, int]]:
    """What the no-oracle detector calls objects of assets it was not trained on: the procedural world's
    primitives (benchmarks/perception/scenes.py, other sizes and colours), 2 views per scene. Per truth
    category: the category of the detection that matches it (mask IoU >= 0.5), or ``(not segmented)``."""

    detector = load_detector(weights)
    out: dict[str, dict[str, int]] = {}
    for ss in np.random.SeedSequence([seed, 4242]).spawn(scenes):
        frames, _ = procedural_scene(int(ss.generate_state(1)[0]), 2, 640, 480)
        for frame in frames:
            dets = [d for d in detector.detect(frame.rgb, frame.depth, frame.camera) if d.category != "table"]
            ids, counts = np.unique(frame.masks[frame.masks >= 0], return_counts=True)
            for i, n in zip(ids.tolist(), counts.tolist(), strict=True):
                cat, _ = target_of(frame, i)
                if cat == "none" or n < 4 * MIN_TRUTH_PIXELS:
                    continue
                truth = frame.masks == i
                best, best_iou = "(not segmented)", 0.5
                for d in dets:
                    iou = float((d.mask & truth).sum()) / float((d.mask | truth).sum())
                    if iou >= best_iou:
                        best, best_iou = d.category, iou
                row = out.setdefault(cat, {})
                row[best] = row.get(best, 0) + 1
    return out


def bench_noise(scenes: int, seed: int, world: str) -> list[dict[str, Any]]:
    """Relation F1 and state accuracy for each depth-noise level and mask erosion."""
    rows = []
    settings = [(n, 0) for n in NOISE] + [(0.0, e) for e in EROSION if e]
    for noise, erosion in settings:
        r = evaluate(scenes, seed, depth_noise=noise, mask_erosion=erosion, world=world)
        rows.append(
            {
                "world": world,
                "depth_noise": noise,
                "mask_erosion": erosion,
                "f1": {rel: s["f1"] for rel, s in r["relations"].items()},
                "visible_f1": {rel: s["f1"] for rel, s in r["visible"]["relations"].items()},
                "node_recall": r["nodes"]["recall"],
                "states": r["states"]["accuracy"],
                "visible_states": r["visible"]["states"]["accuracy"],
                "drawer_opening_mae_m": r["states"]["drawer_opening_mae_m"],
                "door_angle_mae_rad": r["states"]["door_angle_mae_rad"],
            }
        )
    return rows


def markdown(rows: list[dict[str, Any]]) -> str:
    """The noise table as Markdown (relations the world's truth defines; others shown as "-")."""
    rels: list[str] = []
    for row in rows:
        rels += [r for r in row["f1"] if r not in rels]
    head = "| world | depth noise (m) | mask erosion (px) | " + " | ".join(f"F1 {r}" for r in rels)
    head += " | visible F1 on | visible F1 in | node recall | state acc. | visible state acc. |"
    lines = [head, "|" + "---|" * (8 + len(rels))]
    for row in rows:
        cells = [row["world"], f"{row['depth_noise']:g}", str(row["mask_erosion"])]
        cells += [f"{row['f1'][r]:.3f}" if r in row["f1"] else "-" for r in rels]
        cells += [f"{row['visible_f1']['on']:.3f}", f"{row['visible_f1']['in']:.3f}"]
        cells += [f"{row['node_recall']:.3f}", f"{row['states']:.3f}", f"{row['visible_states']:.3f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scenes", type=int, default=30)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", choices=("fps", "noise", "detect", "openset"), default=None)
    ap.add_argument("--weights", default=None, help="detector weights for --only detect (default: shipped)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    out: dict[str, Any] = {}
    if args.only == "openset":
        out["openset"] = bench_openset(args.scenes, args.seed, args.weights)
    if args.only == "detect":
        out["detect"] = bench_detect(max(1, args.frames // 4), args.seed, args.repeats, args.weights)
    if args.only in (None, "fps"):
        out["fps"] = [bench_fps(args.frames, args.seed, args.repeats, w) for w in ("procedural", "skills")]
    if args.only in (None, "noise"):
        out["noise"] = [
            row for w in ("procedural", "skills") for row in bench_noise(args.scenes, args.seed, w)
        ]
    if args.json:
        print(json.dumps(out, indent=2))
        return
    for f in out.get("fps", []):
        print(
            f"{f['world']:>10}: {f['fps']} frames/s wall ({f['ms_per_frame_mean']} ms mean, {f['ms_per_frame_p90']} ms "
            f"p90), {f['fps_cpu']} frames per CPU-second ({f['cpu_ms_per_frame_mean']} ms CPU) over {f['frames']} "
            f"frames at 640x480; load average {f['load_average']} on {f['cpus']} CPUs"
        )
    if "noise" in out:
        print(markdown(out["noise"]))
    for cat, row in out.get("openset", {}).items():
        total = sum(row.values())
        parts = ", ".join(f"{k} {v}" for k, v in sorted(row.items(), key=lambda kv: -kv[1]))
        print(f"{cat:>10} ({total}): {parts}")
    if "detect" in out:
        d = out["detect"]
        for part in ("segmentation", "detection", "pipeline_4_views_per_frame"):
            r = d[part]
            print(
                f"{part:>27}: {r['ms_cpu']} ms CPU ({r['fps_cpu']} frames per CPU-second), {r['ms_wall']} ms wall "
                f"({r['fps']} frames/s) per 640x480 frame"
            )
        print(
            f"{d['frames']} frames, model: {d['model']}; load average {d['load_average']} on {d['cpus']} CPUs"
        )


if __name__ == "__main__":
    main()
