"""Where perception's CPU goes: cProfile (CPU-time clock) over ``perceive`` on rendered skills-world scenes.

``python -m gsr.benchmarks.perception.cpu_profile --scenes 3 --cameras 4 --seed 0 [--no-oracle] [--top 25]``
renders the scenes ``gsr perceive-eval`` renders (same seeds, 640x480), perceives each once untimed (one-off
imports, model loading), then perceives them all under the profiler and prints frames per CPU-second and
the project functions with the most cumulative CPU time. Rendering is outside the profiled region; so is
scoring. ``--no-oracle`` profiles the detector (segmentation, recognition) and the pipeline from RGB-D
alone, as ``perceive-eval --no-oracle`` times them. The profiler's own overhead lowers the figure: compare
runs of this tool with each other, and take speed figures from ``perceive-eval``."""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import sys
import time
from typing import Any

import numpy as np
from gsr.benchmarks.perception.eval import skills_scene
from gsr.perception import perceive
from gsr.perception.detect import load_detector
from gsr.perception.rgbd import View, perceive_rgbd


def scenes(count: int, seed: int, cameras: int, no_oracle: bool) -> list[list[Any]]:
    """The frames of ``count`` scenes exactly as ``perceive-eval`` seeds them."""
    out = []
    for ss in np.random.SeedSequence(seed).spawn(count):
        frames, _ = skills_scene(int(ss.generate_state(1)[0]), cameras, 640, 480, self_filter=no_oracle)
        out.append(frames)
    return out


def profile(frame_sets: list[list[Any]], no_oracle: bool) -> tuple[pstats.Stats, float, int]:
    """Perceive every scene under a CPU-time profiler: (stats, CPU seconds, frames)."""
    if no_oracle:
        detector = load_detector()
        inputs = [[View(f.rgb, f.depth, f.camera) for f in fs] for fs in frame_sets]

        def run(views: list[Any]) -> Any:
            return perceive_rgbd(views, detector)[0]
    else:
        inputs = frame_sets
        run = perceive
    run(inputs[0])  # one-off imports and model loading are not a per-frame cost
    prof = cProfile.Profile(time.process_time)
    start = time.process_time()
    prof.enable()
    for scene in inputs:
        run(scene)
    prof.disable()
    cpu = time.process_time() - start
    return pstats.Stats(prof), cpu, sum(len(s) for s in inputs)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=3)
    ap.add_argument("--cameras", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-oracle", action="store_true", help="RGB-D only: the detector and the pipeline")
    ap.add_argument("--top", type=int, default=25, help="how many functions to print")
    args = ap.parse_args(argv)
    if args.scenes < 1 or args.cameras < 1 or args.top < 1:
        print(
            "gsr.benchmarks.perception.cpu_profile: --scenes, --cameras and --top must be >= 1",
            file=sys.stderr,
        )
        return 2
    stats, cpu, frames = profile(scenes(args.scenes, args.seed, args.cameras, args.no_oracle), args.no_oracle)
    path = "no-oracle" if args.no_oracle else "oracle masks"
    print(
        f"{path}: {frames} frames, {cpu:.2f} CPU s under the profiler, {frames / cpu:.2f} frames per CPU-second"
    )
    text = io.StringIO()
    stats.stream = text  # type: ignore[attr-defined]
    stats.sort_stats("cumulative").print_stats(r"perception/", args.top)
    table = text.getvalue()
    print(table[table.find("ncalls") :] if "ncalls" in table else table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
