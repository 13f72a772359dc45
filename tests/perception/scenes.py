"""Hand-built PyBullet scenes with known answers, shared by the perception tests."""

from __future__ import annotations

import numpy as np
from gsr.benchmarks.perception.render import render, table_camera
from gsr.benchmarks.perception.scenes import Scene, SceneBuilder
from gsr.perception.frame import Frame
from gsr.skills.camera import CameraSpec

FRONT = table_camera((-0.1, 0.0, 0.95))
LEFT = table_camera((0.3, 0.7, 0.8))


def hand_scene() -> tuple[Scene, dict[str, np.ndarray]]:
    """Stack, adjacent pair, box with a cube, plate with a cube, cabinet (one drawer open), microwave."""
    b = SceneBuilder(np.random.default_rng(7))
    b.table()
    a = b.box_object("cube", "red", np.full(3, 0.025), np.array([0.5, 0.2]), 0.0, 0.3, ("on", "table"))
    b.box_object("block", "blue", np.full(3, 0.02), np.array([0.5, 0.2]), 0.05, 0.0, ("on", a.node))
    b.box_object("cube", "green", np.full(3, 0.02), np.array([0.5, 0.27]), 0.0, 0.0, ("on", "table"))
    box = b.open_box("purple", np.array([0.56, -0.1]), 0.4)
    b.box_object("cube", "orange", np.full(3, 0.02), box.center[:2], box.floor, 0.4, ("in", box.node))
    plate = b.box_object(
        "plate", "yellow", np.array([0.09, 0.09, 0.008]), np.array([0.4, 0.0]), 0.0, 0.0, ("on", "table")
    )
    b.box_object("cube", "cyan", np.full(3, 0.02), np.array([0.4, 0.0]), 0.016, 0.2, ("on", plate.node))
    b.cabinet(np.array([0.95, 0.3]), 0.15, 2, [0.15, 0.0])
    b.microwave(np.array([0.97, -0.5]), -0.1, 1.1)
    import pybullet as pb

    # each handle is a link labelled as its drawer's keypoint; its position is the link's world frame
    handles = {
        label.keypoint_of: np.array(
            pb.getLinkState(seg & ((1 << 24) - 1), (seg >> 24) - 1, physicsClientId=b.scene.client)[4]
        )
        for seg, label in b.scene.labels.items()
        if label.keypoint_of and label.name == "handle"
    }
    return b.scene, handles


def frames(scene: Scene, *specs: CameraSpec) -> list[Frame]:
    """Render the scene from each camera."""
    return [render(scene, s) for s in specs]
