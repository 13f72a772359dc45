"""Perception evaluation harness: render random PyBullet scenes, perceive them, score against ground truth.

Used by ``gsr perceive-eval`` and benchmarks/bench_perception.py. Rendering, noise and mask erosion are
outside the timed region: ``fps`` is frames per second of :func:`perception.perceive` alone.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from perception.corrupt import add_depth_noise, erode_masks
from perception.evaluate import Score
from perception.frame import Frame
from perception.pipeline import PerceptionParams, perceive


def degrade(frame: Frame, depth_noise: float, mask_erosion: int, rng: np.random.Generator) -> Frame:
    """The frame with Gaussian depth noise (m) and eroded masks (px)."""
    if depth_noise == 0 and mask_erosion == 0:
        return frame
    return Frame(
        rgb=frame.rgb,
        depth=add_depth_noise(frame.depth, depth_noise, rng),
        masks=erode_masks(frame.masks, mask_erosion),
        camera=frame.camera,
        labels=frame.labels,
    )


def evaluate(
    scenes: int,
    seed: int = 0,
    depth_noise: float = 0.0,
    mask_erosion: int = 0,
    cameras: int = 1,
    width: int = 640,
    height: int = 480,
    params: PerceptionParams | None = None,
) -> dict[str, Any]:
    """Score perception on ``scenes`` random scenes (deterministic per seed); returns the report dict."""
    from benchmarks.perception_scenes import camera_specs, random_scene, render

    if scenes < 1:
        raise ValueError("scenes must be >= 1")
    if cameras < 1:
        raise ValueError("cameras must be >= 1")
    score = Score()
    seconds = 0.0
    frames_seen = 0
    warmed = False
    seeds = np.random.SeedSequence(seed).spawn(scenes)
    for ss in seeds:
        scene_seed = int(ss.generate_state(1)[0])
        rng = np.random.default_rng(scene_seed)
        scene = random_scene(scene_seed)
        try:
            frames = [render(scene, spec) for spec in camera_specs(rng, cameras, width, height)]
            truth = scene.truth()
        finally:
            scene.close()
        frames = [degrade(f, depth_noise, mask_erosion, rng) for f in frames]
        if not warmed:  # first call pays one-off imports (open3d); not a per-frame cost
            perceive(frames, params)
            warmed = True
        start = time.perf_counter()
        graph = perceive(frames, params)
        seconds += time.perf_counter() - start
        frames_seen += len(frames)
        score.add(graph, truth)
    report = score.to_dict()
    report.update(
        seed=seed,
        depth_noise=depth_noise,
        mask_erosion=mask_erosion,
        cameras=cameras,
        resolution=[width, height],
        world="benchmarks.perception_scenes",
        perception_seconds=round(seconds, 4),
        fps=round(frames_seen / seconds, 2) if seconds > 0 else None,
    )
    return report


def format_report(report: dict[str, Any]) -> str:
    """A plain-text table of the report."""
    lines = [
        f"scenes {report['scenes']}  seed {report['seed']}  cameras {report['cameras']}  "
        f"{report['resolution'][0]}x{report['resolution'][1]}  depth noise {report['depth_noise']} m  "
        f"mask erosion {report['mask_erosion']} px",
        f"nodes: recall {report['nodes']['recall']:.3f}  precision {report['nodes']['precision']:.3f}  "
        f"({report['nodes']['found']}/{report['nodes']['truth']})",
        f"{'relation':<10} {'precision':>9} {'recall':>7} {'f1':>6} {'tp':>5} {'fp':>5} {'fn':>5}",
    ]
    for rel, s in report["relations"].items():
        lines.append(
            f"{rel:<10} {s['precision']:>9.3f} {s['recall']:>7.3f} {s['f1']:>6.3f} {s['tp']:>5} {s['fp']:>5} {s['fn']:>5}"
        )
    st = report["states"]
    lines.append(
        f"states: accuracy {st['accuracy']:.3f} ({st['correct']}/{st['total']}; "
        f"{st['observed']} observed, accuracy among observed {st['accuracy_observed']:.3f})  "
        f"drawer opening MAE {st['drawer_opening_mae_m']} m  door angle MAE {st['door_angle_mae_rad']} rad"
    )
    lines.append(f"perception: {report['fps']} frames/s ({report['perception_seconds']} s in perceive)")
    return "\n".join(lines)
