"""Which cameras does perception need in the skills world? F1 of ``on``/``in`` per set of views, same scenes.

Run: ``python benchmarks/perception/views.py [--scenes 25] [--seed 0] [--json]
[--set NAME=view,view,...]...``. Every scene (the random GSR-Bench-style tasks of
``gsr perceive-eval --world skills``, same seeds) is rendered once from every view named in any set
(640x480); each set is perceived (fused) and scored against ``scene_graph_from_sim``, over all truth and
over the perceivable relations (both ends shown by one of that set's cameras). Views: the ``gsr.skills.camera.default_views`` (``front``, ``top``,
``left``, ``right``) and three placed across the table from the robot (``back``, ``back_left``,
``back_right``), where the arm does not stand between camera and table. The last line of the report
counts the truth support edges no camera of the largest set sees, by what hides them.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np
from gsr.benchmarks.perception.eval import (
    perceivable_prediction,
    perceivable_truth,
    visible_nodes,
    with_graph_attributes,
)
from gsr.benchmarks.suites.gsr_bench_gen import CELLS, LEVELS, generate_cell
from gsr.perception import perceive
from gsr.perception.evaluate import Score
from gsr.skills.build import build_world
from gsr.skills.camera import CameraSpec, default_views, render_frame
from gsr.skills.sim_graph import scene_graph_from_sim

DEFAULT_SETS = {
    "top": ("top",),
    "top+left": ("top", "left"),
    "default 4": ("front", "top", "left", "right"),
    "default 4 + back": ("front", "top", "left", "right", "back"),
    "top + ring of 4": ("top", "left", "right", "back_left", "back_right"),
    "all 7": ("front", "top", "left", "right", "back", "back_left", "back_right"),
}


def views(world: Any) -> dict[str, Any]:
    """The default views plus three from the far side of the table (facing the robot)."""

    out = dict(default_views(world))
    lo, hi = world.body_aabb(world.table_body)
    cx, cy, cz = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]
    target = (cx, cy, cz + 0.05)
    out["back"] = CameraSpec((hi[0] + 0.6, cy, cz + 0.9), target)
    out["back_left"] = CameraSpec((hi[0] + 0.4, cy + 0.7, cz + 0.8), target)
    out["back_right"] = CameraSpec((hi[0] + 0.4, cy - 0.7, cz + 0.8), target)
    return out


def _hider(target: str) -> str:
    """What hides a support edge's subject, named by its supporter."""
    for word in ("drawer", "lid_box", "cabinet"):
        if word in target:
            return word
    return "other"


def study(scenes: int, seed: int, sets: dict[str, tuple[str, ...]]) -> dict[str, Any]:
    """Scores per view set over the same ``scenes`` skills-world scenes (deterministic per seed)."""
    import random

    needed = sorted({v for names in sets.values() for v in names})
    largest = max(sets, key=lambda k: len(sets[k]))
    scores = {k: (Score(), Score()) for k in sets}
    hidden: dict[str, int] = {}
    for ss in np.random.SeedSequence(seed).spawn(scenes):
        scene_seed = int(ss.generate_state(1)[0])
        pick = random.Random(scene_seed)  # the same task choice as eval.skills_scene
        task = generate_cell(pick.choice(CELLS), pick.choice(LEVELS), n=1, seed=scene_seed)[0]
        world = build_world(task, seed=scene_seed)
        try:
            specs = views(world)
            unknown = [v for v in needed if v not in specs]
            if unknown:
                raise SystemExit(f"unknown view(s) {unknown}; choose from {sorted(specs)}")
            frames = {
                v: with_graph_attributes(
                    render_frame(world, dataclasses.replace(specs[v], width=640, height=480)), world.graph
                )
                for v in needed
            }
            truth = scene_graph_from_sim(world)
        finally:
            world.close()
        for name, names in sets.items():
            chosen = [frames[v] for v in names]
            graph = perceive(chosen)
            seen = visible_nodes(chosen)
            scores[name][0].add(graph, truth, ("on", "in"))
            scores[name][1].add(
                perceivable_prediction(graph, truth, seen), perceivable_truth(truth, seen), ("on", "in")
            )
            if name == largest:
                for e in truth.edges:
                    if e.relation in ("on", "in") and e.source not in seen:
                        key = f"{e.relation} {_hider(e.target)}"
                        hidden[key] = hidden.get(key, 0) + 1
    rows = {}
    for name, (all_, vis) in scores.items():
        a, v = all_.to_dict(), vis.to_dict()
        rows[name] = {
            "views": list(sets[name]),
            "node_recall": a["nodes"]["recall"],
            "f1": {r: a["relations"][r]["f1"] for r in ("on", "in")},
            "visible_f1": {r: v["relations"][r]["f1"] for r in ("on", "in")},
            "state_accuracy": a["states"]["accuracy"],
        }
    return {"scenes": scenes, "seed": seed, "sets": rows, "unseen_support_edges": {largest: hidden}}


def markdown(report: dict[str, Any]) -> str:
    """The report as a Markdown table plus the unseen-edge count."""
    lines = [
        "| views | node recall | F1 on | F1 in | perceivable F1 on | perceivable F1 in | state acc. |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, r in report["sets"].items():
        lines.append(
            f"| {name} ({', '.join(r['views'])}) | {r['node_recall']:.3f} | {r['f1']['on']:.3f} | "
            f"{r['f1']['in']:.3f} | {r['visible_f1']['on']:.3f} | {r['visible_f1']['in']:.3f} | "
            f"{r['state_accuracy']:.3f} |"
        )
    for name, counts in report["unseen_support_edges"].items():
        total = sum(counts.values())
        parts = ", ".join(f"{k}: {n}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1]))
        lines.append(f"\nTruth support edges whose subject no camera of '{name}' sees: {total} ({parts}).")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=25)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--set", action="append", default=[], help="NAME=view,view,... (repeatable)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if args.scenes < 1:
        ap.error("--scenes must be at least 1")
    sets = dict(DEFAULT_SETS)
    if args.set:
        sets = {}
        for item in args.set:
            name, sep, names = item.partition("=")
            if not sep or not name or not names:
                ap.error(f"--set {item!r}: expected NAME=view,view,...")
            sets[name] = tuple(v.strip() for v in names.split(",") if v.strip())
    report = study(args.scenes, args.seed, sets)
    print(json.dumps(report, indent=2) if args.json else markdown(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
