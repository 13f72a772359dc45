"""The pipeline on rendered scenes with known answers: relations, states, keypoints, fusion, plug-ins."""

from __future__ import annotations

import numpy as np
import pytest
from gsr.perception.evaluate import score
from gsr.perception.frame import Detector, Frame, InstanceLabel, frame_from_detector
from gsr.perception.pipeline import perceive

pytest.importorskip("pybullet")
pytest.importorskip("open3d")

from tests.perception.scenes import FRONT, LEFT, frames, hand_scene


@pytest.fixture(scope="module")
def rendered():
    scene, handles = hand_scene()
    try:
        views = frames(scene, FRONT, LEFT)
        truth = scene.truth()
    finally:
        scene.close()
    return views, truth, handles


def _keys(graph, relations=None):
    return {e.key() for e in graph.edges if relations is None or e.relation in relations}


def test_single_view_graph_matches_ground_truth(rendered):
    views, truth, _ = rendered
    graph = perceive(views[0])
    assert _keys(graph) == _keys(truth)  # on, in, adjacent and all four directions
    assert {n.id for n in graph.nodes} == {n.id for n in truth.nodes}
    assert ("blue_block_1", "on", "red_cube_1") in _keys(graph)
    assert ("orange_cube_1", "in", "purple_box_1") in _keys(graph)
    assert ("cyan_cube_1", "on", "yellow_plate_1") in _keys(graph)
    assert ("green_cube_1", "adjacent", "red_cube_1") in _keys(graph)
    assert ("green_cube_1", "left_of", "red_cube_1") in _keys(graph)  # +y is the robot's left


def test_articulated_states_and_measurements(rendered):
    views, _, _ = rendered
    nodes = perceive(views[0]).node_map()
    assert nodes["cabinet_1/drawer_low"].states == ("open",)
    assert nodes["cabinet_1/drawer_high"].states == ("closed",)
    assert nodes["microwave_1/door"].states == ("open",)
    assert nodes["cabinet_1/drawer_low"].attributes["open_distance"] == pytest.approx(0.15, abs=0.005)
    assert nodes["cabinet_1/drawer_high"].attributes["open_distance"] == pytest.approx(0.0, abs=0.005)
    assert nodes["microwave_1/door"].attributes["open_angle"] == pytest.approx(1.1, abs=0.03)
    assert nodes["cabinet_1/drawer_low"].parent == "cabinet_1"


def test_drawer_levels_ranked_by_height(rendered):
    views, _, _ = rendered
    nodes = perceive(views[0]).node_map()
    drawers = sorted(
        (n for n in nodes.values() if n.category == "drawer"), key=lambda n: n.attributes["level"]
    )
    assert [d.attributes["level"] for d in drawers] == list(range(len(drawers)))
    assert nodes["cabinet_1/drawer_low"].attributes["level"] == 0  # labels carry no level: perceived
    assert drawers[-1].id == "cabinet_1/drawer_high"


def test_handle_keypoints_from_handle_masks(rendered):
    views, _, handles = rendered
    nodes = perceive(views[0]).node_map()
    for drawer, true_pos in handles.items():
        (kp,) = nodes[drawer].keypoints
        assert kp.name == "handle"
        assert np.linalg.norm(np.array(kp.position.as_tuple()) - true_pos) < 0.012


def test_geometric_handle_when_the_handle_is_part_of_the_drawer_mask(rendered):
    views, _, handles = rendered
    f = views[0]
    masks = f.masks.copy()
    labels = dict(f.labels)
    for mask_id, label in f.labels.items():
        if label.keypoint_of is not None:  # paint each handle with its drawer's id, drop the label
            drawer_id = next(k for k, v in f.labels.items() if v.id == label.keypoint_of)
            masks[masks == mask_id] = drawer_id
            del labels[mask_id]
    graph = perceive(Frame(rgb=f.rgb, depth=f.depth, masks=masks, camera=f.camera, labels=labels))
    kp = graph.node("cabinet_1/drawer_low").keypoints
    assert kp and kp[0].name == "handle"
    # the handle standing off the panel is not taken for the drawer's front face
    assert graph.node("cabinet_1/drawer_low").attributes["open_distance"] == pytest.approx(0.15, abs=0.005)
    assert graph.node("cabinet_1/drawer_high").attributes["open_distance"] == pytest.approx(0.0, abs=0.005)
    assert np.linalg.norm(np.array(kp[0].position.as_tuple()) - handles["cabinet_1/drawer_low"]) < 0.015


def test_two_views_are_fused_per_node(rendered):
    views, truth, _ = rendered
    graph = perceive(views)
    report = score(graph, truth)
    assert report["relations"]["on"]["f1"] == 1.0 and report["relations"]["in"]["f1"] == 1.0
    assert report["states"]["accuracy"] == 1.0
    assert graph.node("red_cube_1").attributes["views"] == 2
    assert graph.metadata["frames"] == 2


def test_unlabelled_ground_becomes_a_ransac_table(rendered):
    views, truth, _ = rendered
    f = views[0]
    table_ids = [k for k, v in f.labels.items() if v.id == "table"]
    masks = np.where(np.isin(f.masks, table_ids), -1, f.masks)
    labels = {k: v for k, v in f.labels.items() if k not in table_ids}
    graph = perceive(Frame(rgb=f.rgb, depth=f.depth, masks=masks, camera=f.camera, labels=labels))
    assert graph.has_node("table")
    plane = graph.metadata["support_plane"]
    assert plane[2] == pytest.approx(1.0, abs=1e-3) and plane[3] == pytest.approx(0.0, abs=2e-3)
    assert _keys(graph, {"on", "in"}) == _keys(truth, {"on", "in"})


class SegmentationDetector:
    """A detector plug-in that reports the simulator's segmentation without node ids (categories only)."""

    def __init__(self, masks: np.ndarray, labels: dict[int, InstanceLabel]) -> None:
        self.masks, self.labels = masks, labels

    def detect(self, rgb, depth):
        assert rgb.ndim == 3 and depth.ndim == 2
        anon = {
            k: InstanceLabel(category=v.category, parent=None)
            for k, v in self.labels.items()
            if v.id is not None
        }
        return self.masks, anon


def test_detector_plug_in_and_anonymous_fusion(rendered):
    views, _, _ = rendered
    detected = [
        frame_from_detector(f.rgb, f.depth, f.camera, SegmentationDetector(f.masks, f.labels)) for f in views
    ]
    assert isinstance(SegmentationDetector(views[0].masks, {}), Detector)
    single = perceive(detected[0])
    fused = perceive(detected)
    cubes = lambda g: sorted(n.id for n in g.nodes if n.category == "cube")  # noqa: E731
    assert cubes(single) == ["cube_1", "cube_2", "cube_3", "cube_4"]
    assert cubes(fused) == cubes(single)  # the second view's cubes merged, not duplicated
    assert all(n.attributes["views"] == 2 for n in fused.nodes if n.category == "cube")
    colours = sorted(n.attributes["color"] for n in single.nodes if n.category == "cube")
    assert colours == ["cyan", "green", "orange", "red"]  # named from the pixels, no label gave them


@pytest.mark.physics
def test_lidded_box_state_from_its_top_surface_in_the_skills_world():
    """A box whose lid is slid off shows its cavity from above; a closed one shows a flat top."""
    import dataclasses

    import pybullet as pb
    from gsr.benchmarks.perception.eval import with_graph_attributes
    from gsr.skills.build import build_world
    from gsr.skills.camera import default_views, render_frame

    from gsr.task_spec import Layout, PlacedObject

    layout = Layout(
        objects=(PlacedObject(id="red_lid_box", asset="box_with_lid", position=(-0.1, 0.1, 0.0)),)
    )
    world = build_world(layout, seed=0)
    try:
        box = world.objects["red_lid_box"]
        seen = {}
        for q in (0.0, 0.17):
            pb.resetJointState(box.body, box.links["lid"], q, physicsClientId=world.client)
            spec = dataclasses.replace(default_views(world)["top"], width=640, height=480)
            frame = with_graph_attributes(render_frame(world, spec), world.graph)
            seen[q] = perceive(frame).node("red_lid_box").states
    finally:
        world.close()
    assert seen == {0.0: ("closed",), 0.17: ("open",)}
