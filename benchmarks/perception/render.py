"""Cameras for the procedural perception scenes: look-at specs and PyBullet TinyRenderer rendering.

:func:`render` returns a ``gsr.perception.Frame`` (through ``gsr.skills.camera.render_frame``, the one
frame path) whose mask ids are PyBullet's segmentation values (``body + (link + 1) << 24``), labelled by
the scene (benchmarks/perception/scenes.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from gsr.benchmarks.perception.scenes import Scene, random_scene
from gsr.perception.camera import save_camera
from gsr.perception.frame import Frame, InstanceLabel
from gsr.skills.camera import RGBD, CameraSpec, render_frame

#: Where the procedural scenes' cameras look: the middle of the table in front of the robot.
TABLE_TARGET = (0.65, 0.0, 0.0)


def table_camera(eye: tuple[float, float, float], width: int = 640, height: int = 480) -> CameraSpec:
    """A camera at ``eye`` looking at the table's middle (:data:`TABLE_TARGET`), 60 deg vertical view."""
    return CameraSpec(eye, TABLE_TARGET, width=width, height=height, far=5.0)


def camera_specs(
    rng: np.random.Generator, count: int = 1, width: int = 640, height: int = 480
) -> list[CameraSpec]:
    """Cameras above the robot looking down at the table; extra cameras come from the sides."""
    specs = [
        table_camera((rng.uniform(-0.15, 0.0), rng.uniform(-0.1, 0.1), rng.uniform(0.85, 1.0)), width, height)
    ]
    for k in range(1, count):
        side = 1.0 if k % 2 else -1.0
        specs.append(
            table_camera(
                (rng.uniform(0.2, 0.4), side * rng.uniform(0.6, 0.8), rng.uniform(0.7, 0.85)), width, height
            )
        )
    return specs


def scene_masks(scene: Scene, img: RGBD) -> tuple[np.ndarray, dict[int, InstanceLabel]]:
    """The offline scenes' masks: PyBullet's segmentation values, labelled by the scene (a ``MaskSource``)."""
    return img.segmentation, dict(scene.labels)


def render(scene: Scene, spec: CameraSpec) -> Frame:
    """A frame of the scene: ``gsr.skills.camera.render_frame`` with the scene's own segmentation labels."""
    return render_frame(scene, spec, masks=scene_masks)


def save_frame(frame: Frame, folder: str | Path) -> dict[str, Path]:
    """Write a frame as the files `gsr perceive` reads: rgb.png, depth.npy, masks.npy, camera.json, labels.json."""
    from PIL import Image

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    files = {name: out / name for name in ("rgb.png", "depth.npy", "masks.npy", "camera.json", "labels.json")}
    Image.fromarray(frame.rgb).save(files["rgb.png"])
    np.save(files["depth.npy"], frame.depth)
    np.save(files["masks.npy"], frame.masks)
    save_camera(frame.camera, files["camera.json"])
    labels = {}
    for k, v in frame.labels.items():
        if v.keypoint_of:
            entry: dict = {"keypoint_of": v.keypoint_of, "name": v.name}
        else:
            entry = {"id": v.id, "category": v.category, "color": v.color, "parent": v.parent}
        labels[str(k)] = {key: val for key, val in entry.items() if val is not None}
    files["labels.json"].write_text(json.dumps(labels, indent=1) + "\n")
    return files


def main() -> None:
    """Render one procedural scene and write its frame files and ground truth (for trying `gsr perceive`)."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True, help="folder for rgb.png, depth.npy, masks.npy, camera.json, ...")
    args = ap.parse_args()
    scene = random_scene(args.seed)
    try:
        frame = render(scene, camera_specs(np.random.default_rng(args.seed))[0])
        truth = scene.truth()
    finally:
        scene.close()
    files = save_frame(frame, args.out)
    (Path(args.out) / "truth.json").write_text(truth.to_json() + "\n")
    print("\n".join(str(p) for p in [*files.values(), Path(args.out) / "truth.json"]))


if __name__ == "__main__":
    main()
