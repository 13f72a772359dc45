"""Labelled RGB-D frames for training the no-oracle detector (``gsr perceive-train``).

Scenes are built by the project's simulator from its own asset library: random GSR-Bench-style tasks
(``gsr.benchmarks.suites.gsr_bench_gen``, all cells and levels) and the shipped LIBERO tasks, each with a
seed of its own, so layouts differ. Every scene is rendered from random camera poses (the world's four
default views, jittered, and free poses on a hemisphere around the table), under a random light
direction and ambient level, and the depth gets random Gaussian noise (0-5 mm). The labels are the
simulator's instance masks (one per scene-graph node, the robot and background unlabelled), which only
training and evaluation read: the detector itself never sees them.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
from gsr.benchmarks.perception.eval import skills_scene
from gsr.benchmarks.suites.gsr_bench_gen import CELLS, LEVELS, generate_cell
from gsr.benchmarks.suites.libero_suite import load_libero
from gsr.perception.corrupt import add_depth_noise
from gsr.perception.detect import SHIPPED_MODEL, RGBDDetector, load_model
from gsr.perception.frame import Frame
from gsr.perception.train import TrainConfig, evaluate, save_model, train
from gsr.skills.build import build_world
from gsr.skills.camera import CameraSpec, Light, default_views, render_frame

from gsr.errors import GSRError
from gsr.resources import data_dir

#: Share of scenes taken from the LIBERO tasks (the rest are generated GSR-Bench tasks).
LIBERO_SHARE = 0.3


def _task(scene_seed: int):
    """A random task (generated GSR-Bench cell/level or a LIBERO task), deterministic per seed."""

    pick = random.Random(scene_seed)
    if pick.random() < LIBERO_SHARE:
        tasks = _libero_tasks()
        if tasks:
            return pick.choice(tasks)
    return generate_cell(pick.choice(CELLS), pick.choice(LEVELS), n=1, seed=scene_seed)[0]


_LIBERO: list = []


def _libero_tasks() -> list:
    if not _LIBERO:
        folder = data_dir() / "libero"
        if folder.is_dir():
            _LIBERO.extend(load_libero(folder))
    return _LIBERO


def camera_poses(world, rng: np.random.Generator, count: int) -> list:
    """``count`` camera specs: jittered default views and free poses on a hemisphere over the table."""

    lo, hi = world.body_aabb(world.table_body)
    cx, cy, cz = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]
    defaults = list(default_views(world).values())
    out = []
    for k in range(count):
        target = (cx + rng.uniform(-0.15, 0.15), cy + rng.uniform(-0.2, 0.2), cz + rng.uniform(0.0, 0.08))
        fov = float(rng.uniform(50.0, 65.0))
        if k < len(defaults) and rng.random() < 0.5:
            d = defaults[k]
            eye = tuple(float(e + rng.uniform(-0.08, 0.08)) for e in d.eye)
            out.append(CameraSpec(eye, d.target, up=d.up, fov=fov, width=640, height=480))
            continue
        radius = rng.uniform(0.9, 1.6)
        elev = math.radians(rng.uniform(25.0, 80.0))
        azim = rng.uniform(-math.pi, math.pi)
        eye = (
            target[0] + radius * math.cos(elev) * math.cos(azim),
            target[1] + radius * math.cos(elev) * math.sin(azim),
            target[2] + radius * math.sin(elev),
        )
        up = (1.0, 0.0, 0.0) if elev > math.radians(85) else (0.0, 0.0, 1.0)
        out.append(CameraSpec(eye, target, up=up, fov=fov, width=640, height=480))
    return out


def render_lit(world, spec, rng: np.random.Generator) -> Frame:
    """Render one labelled frame under a random light (direction, ambient, diffuse)."""
    az, el = rng.uniform(0, 2 * math.pi), rng.uniform(0.3, 1.4)
    direction = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
    ambient = float(rng.uniform(0.4, 0.8))
    light = Light(direction, ambient, float(rng.uniform(0.3, 0.7)))
    return render_frame(world, spec, light=light)


def scene_frames(scene_seed: int, views: int) -> list[Frame]:
    """``views`` labelled, randomly lit and noised frames of one random scene."""

    rng = np.random.default_rng([scene_seed, 7])
    world = build_world(_task(scene_seed), seed=scene_seed)
    try:
        frames = [render_lit(world, spec, rng) for spec in camera_poses(world, rng, views)]
    finally:
        world.close()
    noisy = []
    for f in frames:
        sigma = float(rng.choice([0.0, 0.0, 0.002, 0.005]))
        noisy.append(replace(f, depth=add_depth_noise(f.depth, sigma, rng)) if sigma else f)
    return noisy


def training_frames(seed: int, scenes: int, views: int) -> Iterator[Frame]:
    """Frames of ``scenes`` random scenes (deterministic per ``seed``), ``views`` per scene."""
    for ss in np.random.SeedSequence(seed).spawn(scenes):
        yield from scene_frames(int(ss.generate_state(1)[0]), views)


def heldout_frames(seed: int, scenes: int, cameras: int = 4) -> Iterator[Frame]:
    """Frames exactly as ``gsr perceive-eval`` renders them (default views and light), on held-out seeds."""

    for ss in np.random.SeedSequence([seed, HELDOUT_STREAM]).spawn(scenes):
        frames, _ = skills_scene(int(ss.generate_state(1)[0]), cameras, 640, 480)
        yield from frames


#: Seed streams: training and held-out scene seeds never coincide with each other or with the
#: ``SeedSequence(seed)`` streams of ``gsr perceive-eval``.
TRAIN_STREAM = 2207
HELDOUT_STREAM = 9001


def run_training(
    out: str,
    scenes: int = 150,
    views: int = 6,
    heldout_scenes: int = 20,
    seed: int = 0,
    threads: int = 1,
    epochs: int | None = None,
    log=print,
) -> dict:
    """Render, train, evaluate on held-out scenes, and write the model folder; returns the metadata."""

    total = scenes * views
    link_frames = max(1, total // 6)
    merge_frames = max(1, total // 4)
    config = TrainConfig(link_frames=link_frames, merge_frames=merge_frames, threads=threads, seed=seed)
    if epochs is not None:
        config = replace(config, epochs=epochs)
    note = (
        f"{scenes} random scenes of the project's simulator (gsr.skills.build_world, its procedural asset "
        f"library): generated GSR-Bench tasks of every cell and level and, for {int(LIBERO_SHARE * 100)}% of "
        f"scenes, the 40 shipped LIBERO tasks, each with its own layout seed (seed stream "
        f"[{seed}, {TRAIN_STREAM}]); {views} views per scene at 640x480 (jittered default views and random "
        "poses on a hemisphere over the table, 50-65 degree field of view), random light direction, "
        "ambient and diffuse levels, Gaussian depth noise of 0, 2 or 5 mm."
    )
    model = train(
        (
            f
            for ss in np.random.SeedSequence([seed, TRAIN_STREAM]).spawn(scenes)
            for f in scene_frames(int(ss.generate_state(1)[0]), views)
        ),
        config,
        log,
        note,
    )
    heldout = None
    if heldout_scenes > 0:
        log(f"held-out evaluation: {heldout_scenes} scenes x 4 default views")
        results = evaluate(
            heldout_frames(seed, heldout_scenes),
            {
                "geometry + trained model": RGBDDetector(model),
                "geometry + rules (no weights)": RGBDDetector(None),
            },
        )
        heldout = {
            "note": f"{heldout_scenes} generated GSR-Bench scenes (seed stream [{seed}, {HELDOUT_STREAM}]), "
            "rendered exactly as `gsr perceive-eval` does (4 default views, default light, no noise).",
            "results": results,
        }
    folder = save_model(model, out, heldout)
    load_model(folder)
    meta = dict(model.card)
    meta["heldout"] = heldout
    return meta


def compare_heldout(weights: list[str], seed: int = 0, scenes: int = 20) -> dict:
    """The model card's held-out evaluation for several weight folders on the same frames.

    ``weights``: ``gsr perceive-train`` output folders; ``shipped`` names the shipped weights and ``rules``
    geometry without weights. Frames are those of the card (``heldout_frames(seed, scenes)``, 4 default
    views), rendered once by the simulator of the current tree, so weights trained before a rendering
    change are scored on today's renders beside the new ones."""
    detectors = {}
    for w in weights:
        if w == "rules":
            detectors[w] = RGBDDetector(None)
        elif w == "shipped":
            detectors[w] = RGBDDetector(load_model(SHIPPED_MODEL))
        else:
            detectors[w] = RGBDDetector(load_model(w))
    return evaluate(heldout_frames(seed, scenes), detectors)


def main(argv: list[str] | None = None) -> int:
    """``python -m gsr.benchmarks.perception.train_data WEIGHTS... [--seed 0] [--scenes 20]``: JSON report."""
    ap = argparse.ArgumentParser(description=compare_heldout.__doc__.splitlines()[0])
    ap.add_argument("weights", nargs="+", help="weight folders, 'shipped' or 'rules'")
    ap.add_argument("--seed", type=int, default=0, help="seed of the held-out stream (the card's: 0)")
    ap.add_argument("--scenes", type=int, default=20)
    args = ap.parse_args(argv)
    try:
        report = compare_heldout(args.weights, args.seed, args.scenes)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
