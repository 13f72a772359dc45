"""Can the perception scenes' bodies go through the skills layer's URDF writer without changing a frame?

The offline scenes (``scenes.SceneBuilder``) build each body with PyBullet's ``createVisualShapeArray`` /
``createMultiBody``; the skills worlds load URDF text from ``gsr.skills.urdf.urdf_text``. This check
builds the same random scenes both ways (the second through a PyBullet stand-in that records the visual
shapes and turns each ``createMultiBody`` into ``urdf_text`` links, joints included, and ``loadURDF``),
renders the same cameras, and reports the largest RGB / depth / mask differences and whether the labels
and truth graphs are equal. ``--unique-materials`` renames the writer's per-link material names
(``m0``, ``m1``, ... repeat across links, and PyBullet keeps the first colour given to a name).

    python -m gsr.benchmarks.perception.builder_check --scenes 3 [--unique-materials] [--json]
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import re
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from gsr.benchmarks.perception import eval as perception_eval
from gsr.benchmarks.perception.render import camera_specs, render
from gsr.benchmarks.perception.scenes import Scene, SceneBuilder, random_scene
from gsr.skills.urdf import Joint, Link, Shape, urdf_text


def _unique_materials(text: str) -> str:
    count = itertools.count()
    return re.sub(r'<material name="m\d+">', lambda _m: f'<material name="u{next(count)}">', text)


class UrdfBullet:
    """PyBullet for ``SceneBuilder`` with every multibody loaded from ``urdf_text`` instead."""

    def __init__(self, folder: Path, unique_materials: bool) -> None:
        import pybullet

        self._pb = pybullet
        self._folder = folder
        self._unique = unique_materials
        self._shapes: dict[int, list[Shape]] = {}
        self._joint_types = {
            pybullet.JOINT_PRISMATIC: "prismatic",
            pybullet.JOINT_REVOLUTE: "revolute",
            pybullet.JOINT_FIXED: "fixed",
        }

    def __getattr__(self, name: str) -> Any:
        return getattr(self._pb, name)

    def _record(self, shapes: list[Shape]) -> int:
        sid = -10 - len(self._shapes)  # never a real shape id
        self._shapes[sid] = shapes
        return sid

    def createVisualShapeArray(
        self, shapeTypes, halfExtents, visualFramePositions, rgbaColors, physicsClientId
    ) -> int:
        assert all(t == self._pb.GEOM_BOX for t in shapeTypes)
        return self._record(
            [
                Shape(
                    "box",
                    tuple(map(float, o)),
                    tuple(2.0 * float(x) for x in h),
                    tuple(map(float, c)),
                    collide=False,
                )
                for h, o, c in zip(halfExtents, visualFramePositions, rgbaColors, strict=True)
            ]
        )

    def createVisualShape(
        self, shapeType, halfExtents, rgbaColor, physicsClientId, visualFramePosition=(0.0, 0.0, 0.0)
    ) -> int:
        assert shapeType == self._pb.GEOM_BOX
        shape = Shape(
            "box",
            tuple(map(float, visualFramePosition)),
            tuple(2.0 * float(x) for x in halfExtents),
            tuple(map(float, rgbaColor)),
            collide=False,
        )
        return self._record([shape])

    def createMultiBody(
        self, baseMass, baseVisualShapeIndex, basePosition, baseOrientation, physicsClientId, **links
    ) -> int:
        out = [Link("base", tuple(self._shapes[baseVisualShapeIndex]), float(baseMass))]
        for i, vis in enumerate(links.get("linkVisualShapeIndices", [])):
            parent = links["linkParentIndices"][i]
            joint = Joint(
                self._joint_types[links["linkJointTypes"][i]],
                tuple(map(float, links["linkPositions"][i])),
                tuple(map(float, links["linkJointAxis"][i])),
                -3.2,
                3.2,
            )
            out.append(
                Link(
                    f"l{i}", tuple(self._shapes[vis]), 0.0, "base" if parent == 0 else f"l{parent - 1}", joint
                )
            )
        text = urdf_text("scene_body", out)
        if self._unique:
            text = _unique_materials(text)
        path = self._folder / f"{hashlib.sha256(text.encode()).hexdigest()[:16]}.urdf"
        path.write_text(text)
        return self._pb.loadURDF(
            str(path), basePosition, baseOrientation, useFixedBase=True, physicsClientId=physicsClientId
        )


def _frames(scene: Scene, seed: int, cameras: int, width: int, height: int) -> list[Any]:
    try:
        return [render(scene, s) for s in camera_specs(np.random.default_rng(seed), cameras, width, height)]
    finally:
        scene.close()


def _urdf_scene(seed: int, folder: Path, unique_materials: bool) -> Scene:
    original = SceneBuilder.__init__

    def init(self: SceneBuilder, rng: np.random.Generator) -> None:
        original(self, rng)
        self.pb = UrdfBullet(folder, unique_materials)

    SceneBuilder.__init__ = init  # type: ignore[method-assign]
    try:
        return random_scene(seed)
    finally:
        SceneBuilder.__init__ = original  # type: ignore[method-assign]


def compare(
    scenes: int,
    seed: int = 0,
    cameras: int = 4,
    width: int = 320,
    height: int = 240,
    unique_materials: bool = False,
) -> dict[str, Any]:
    """Largest differences between the two builders' frames over ``scenes`` random scenes."""
    diff = {k: {"max": 0.0, "pixels": 0, "of": 0} for k in ("rgb", "depth", "masks")}
    labels_equal = truth_equal = True
    with tempfile.TemporaryDirectory() as tmp:
        for s in range(seed, seed + scenes):
            ref_scene = random_scene(s)
            ref_truth, ref_labels = ref_scene.truth().to_json(), dict(ref_scene.labels)
            ref = _frames(ref_scene, s, cameras, width, height)
            alt_scene = _urdf_scene(s, Path(tmp), unique_materials)
            alt_truth, alt_labels = alt_scene.truth().to_json(), dict(alt_scene.labels)
            alt = _frames(alt_scene, s, cameras, width, height)
            labels_equal &= ref_labels == alt_labels
            truth_equal &= ref_truth == alt_truth
            for a, b in zip(ref, alt, strict=True):
                for key in diff:
                    d = np.abs(getattr(a, key).astype(np.float64) - getattr(b, key).astype(np.float64))
                    diff[key]["max"] = max(diff[key]["max"], float(d.max()))
                    diff[key]["pixels"] += int((d > 0).sum())
                    diff[key]["of"] += int(d.size)
    return {
        "scenes": scenes,
        "seed": seed,
        "cameras": cameras,
        "size": [width, height],
        "unique_materials": unique_materials,
        "labels_equal": labels_equal,
        "truth_equal": truth_equal,
        "diff": diff,
    }


_TIMING_KEYS = ("fps", "seconds", "cpu", "ms", "detector", "pipeline")


def _untimed(report: Any) -> Any:
    if isinstance(report, dict):
        return {k: _untimed(v) for k, v in report.items() if not any(t in k for t in _TIMING_KEYS)}
    return report


def eval_equal(scenes: int, seed: int, cameras: int, oracle: bool) -> bool:
    """Whether ``gsr perceive-eval --world procedural`` reports the same (timings aside) on the two builders."""
    ref = _untimed(
        perception_eval.evaluate(scenes=scenes, seed=seed, cameras=cameras, world="procedural", oracle=oracle)
    )
    original = perception_eval.random_scene
    with tempfile.TemporaryDirectory() as tmp:
        perception_eval.random_scene = lambda s: _urdf_scene(s, Path(tmp), True)
        try:
            alt = _untimed(
                perception_eval.evaluate(
                    scenes=scenes, seed=seed, cameras=cameras, world="procedural", oracle=oracle
                )
            )
        finally:
            perception_eval.random_scene = original
    return ref == alt


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cameras", type=int, default=4)
    ap.add_argument(
        "--unique-materials", action="store_true", help="rename the URDF writer's per-link materials"
    )
    ap.add_argument("--json", action="store_true")
    ap.add_argument(
        "--eval",
        choices=("oracle", "no-oracle"),
        help="also compare the procedural perceive-eval report (unique materials) from --seed",
    )
    args = ap.parse_args(argv)
    if args.scenes < 1 or args.cameras < 1:
        print("gsr.benchmarks.perception.builder_check: --scenes and --cameras must be >= 1", file=sys.stderr)
        return 2
    report = compare(args.scenes, args.seed, args.cameras, unique_materials=args.unique_materials)
    if args.eval:
        report["eval_equal"] = eval_equal(args.scenes, args.seed, args.cameras, args.eval == "oracle")
    if args.json:
        print(json.dumps(report, indent=1))
        return 0
    print(f"{args.scenes} scenes from seed {args.seed}, {args.cameras} cameras each, 320x240")
    print(f"labels equal: {report['labels_equal']}, truth graphs equal: {report['truth_equal']}")
    for key, d in report["diff"].items():
        share = 100.0 * d["pixels"] / max(d["of"], 1)
        print(f"{key}: max |difference| {d['max']:.6g}, differing {d['pixels']} of {d['of']} ({share:.3f}%)")
    if args.eval:
        print(
            f"perceive-eval --world procedural ({args.eval}) report equal, timings aside: {report['eval_equal']}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
