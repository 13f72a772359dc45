"""The offline perception scenes build their bodies through the skills layer's URDF writer.

``gsr.benchmarks.perception.scenes.load_body`` writes each body with ``gsr.skills.urdf.urdf_text`` and loads
it. The reference here loads the same ``Link`` objects with PyBullet's ``createMultiBody`` directly (the
way the scenes were built before they shared the writer), so a writer that drops, moves or recolours a
shape, or breaks a joint, shows up as differing frames: 3 random scenes x 4 cameras are rendered both
ways and compared.
"""

from __future__ import annotations

import numpy as np
import pytest

pb = pytest.importorskip("pybullet")

from gsr.benchmarks.perception import scenes  # noqa: E402
from gsr.benchmarks.perception.render import camera_specs, render  # noqa: E402
from gsr.skills.urdf import Link  # noqa: E402

_JOINTS = {"prismatic": pb.JOINT_PRISMATIC, "revolute": pb.JOINT_REVOLUTE, "fixed": pb.JOINT_FIXED}


def _visual(client: int, link: Link) -> int:
    assert all(s.kind == "box" for s in link.shapes)
    return pb.createVisualShapeArray(
        shapeTypes=[pb.GEOM_BOX] * len(link.shapes),
        halfExtents=[[x / 2.0 for x in s.size] for s in link.shapes],
        visualFramePositions=[list(s.xyz) for s in link.shapes],
        rgbaColors=[list(s.rgba) for s in link.shapes],
        physicsClientId=client,
    )


def multibody(client: int, links: list[Link], position, yaw: float) -> tuple[int, dict[str, int]]:
    """``scenes.load_body`` without URDF: the links as one ``createMultiBody`` (links in the given order)."""
    rest = links[1:]
    index = {link.name: i for i, link in enumerate(rest)}
    body = pb.createMultiBody(
        baseMass=0,
        baseVisualShapeIndex=_visual(client, links[0]),
        basePosition=list(map(float, position)),
        baseOrientation=pb.getQuaternionFromEuler((0.0, 0.0, yaw)),
        linkMasses=[0.0] * len(rest),
        linkCollisionShapeIndices=[-1] * len(rest),
        linkVisualShapeIndices=[_visual(client, link) for link in rest],
        linkPositions=[list(link.joint.xyz) for link in rest],
        linkOrientations=[[0, 0, 0, 1]] * len(rest),
        linkInertialFramePositions=[[0, 0, 0]] * len(rest),
        linkInertialFrameOrientations=[[0, 0, 0, 1]] * len(rest),
        linkParentIndices=[0 if link.parent == links[0].name else index[link.parent] + 1 for link in rest],
        linkJointTypes=[_JOINTS[link.joint.type] for link in rest],
        linkJointAxis=[list(link.joint.axis) for link in rest],
        physicsClientId=client,
    )
    return body, {links[0].name: -1, **index}


def _frames(seed: int) -> tuple[list, str, dict]:
    scene = scenes.random_scene(seed)
    try:
        specs = camera_specs(np.random.default_rng(seed), 4, 320, 240)
        return [render(scene, s) for s in specs], scene.truth().to_json(), dict(scene.labels)
    finally:
        scene.close()


def test_urdf_built_scenes_render_as_the_shapes_they_declare(monkeypatch: pytest.MonkeyPatch) -> None:
    urdf = [_frames(seed) for seed in range(3)]
    monkeypatch.setattr(scenes, "load_body", multibody)
    direct = [_frames(seed) for seed in range(3)]
    pixels = 0
    rgb_values = mask_pixels = 0
    depth_max = 0.0
    for (a_frames, a_truth, a_labels), (b_frames, b_truth, b_labels) in zip(urdf, direct, strict=True):
        assert a_truth == b_truth
        assert a_labels == b_labels  # the same segmentation ids: links in the same order, named alike
        for a, b in zip(a_frames, b_frames, strict=True):
            assert a.labels == b.labels
            pixels += a.masks.size
            mask_pixels += int((a.masks != b.masks).sum())
            rgb_values += int((a.rgb != b.rgb).sum())
            depth_max = max(depth_max, float(np.abs(a.depth - b.depth).max()))
    # measured (seeds 0-9): 1 mask pixel of 3.07 M and 3 RGB values of 9.2 M differ, at body edges; the
    # URDF path rounds through text (6 significant digits) and PyBullet's inertial frames: depth <= 2e-5 m
    assert mask_pixels <= pixels * 1e-4
    assert rgb_values <= 3 * pixels * 1e-4
    assert depth_max < 1e-4


def test_load_body_names_its_links_and_leaves_no_file(tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(scenes.tempfile, "tempdir", None)  # re-read TMPDIR
    b = scenes.SceneBuilder(np.random.default_rng(0))
    try:
        parts = b.cabinet(np.array([0.9, 0.0]), 0.0, 3, [0.1, 0.0, 0.2])
        b.microwave(np.array([0.9, 0.5]), 0.0, 1.0)
        client = b.scene.client
        cabinet = next(k for k, v in b.scene.labels.items() if v.id == parts[0].node) & ((1 << 24) - 1)
        opened = [
            pb.getJointState(cabinet, j, physicsClientId=client)[0]
            for j in range(pb.getNumJoints(cabinet, physicsClientId=client))
            if pb.getJointInfo(cabinet, j, physicsClientId=client)[2] == pb.JOINT_PRISMATIC
        ]
        assert opened == pytest.approx([0.1, 0.0, 0.2])
        kinds = sorted(v.name if v.keypoint_of else v.category for v in b.scene.labels.values())
        assert kinds == [
            "cabinet",
            "door",
            "drawer",
            "drawer",
            "drawer",
            "handle",
            "handle",
            "handle",
            "microwave",
        ]
        drawers = {v.keypoint_of for v in b.scene.labels.values() if v.keypoint_of}
        assert drawers == {p.node for p in parts[1:]}
    finally:
        b.scene.close()
    assert list(tmp_path.iterdir()) == []
