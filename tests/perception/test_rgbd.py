"""Perception from RGB-D alone: detections without ids, fusion across cameras, parts, tracking, bad input."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

pytest.importorskip("pybullet")
pytest.importorskip("open3d")

from gsr.perception.match import NodeScore, match_nodes
from gsr.perception.rgbd import Timing, View, check_view, frame_from_detections, perceive_rgbd
from gsr.perception.track import Tracker, rename_graph

from gsr.errors import GSRError
from gsr.scene_graph import BoundingBox, Node, SceneGraph, Vec3
from tests.perception.scenes import FRONT, LEFT, frames, hand_scene


@dataclass(frozen=True)
class Det:
    """The fields of gsr.perception.detect.Detection that perception reads."""

    mask: np.ndarray
    category: str
    score: float = 0.9
    color: str | None = None
    size: tuple = ()
    extra: dict = field(default_factory=dict)


class SegmentationDetector:
    """A detector with perfect masks and categories but no ids, parents or colours (tests the wiring only)."""

    def __init__(self, views):
        self.by_rgb = {id(f.rgb): f for f in views}

    def detect(self, rgb, depth, camera):
        f = self.by_rgb[id(rgb)]
        out = []
        for k, lab in f.labels.items():
            if lab.id is None or lab.keypoint_of is not None:
                continue
            mask = f.masks == k
            if mask.any() and lab.category != "table":
                out.append(Det(mask=mask, category=lab.category))
        return out


@pytest.fixture(scope="module")
def rendered():
    scene, _ = hand_scene()
    try:
        views = frames(scene, FRONT, LEFT)
        truth = scene.truth()
    finally:
        scene.close()
    return views, truth


def _views(frames_):
    return [View(f.rgb, f.depth, f.camera) for f in frames_]


def test_ids_are_made_by_perception_and_views_fuse(rendered):
    frames_, _ = rendered
    det = SegmentationDetector(frames_)
    single, _ = perceive_rgbd(_views(frames_[:1]), det)
    fused, _ = perceive_rgbd(_views(frames_), det)
    for n in fused.nodes:  # ids are <category>_<k> (parts: <parent>/<category>_<k>), not the truth's names
        assert n.id.rsplit("/", 1)[-1].rsplit("_", 1)[0] == n.category or n.id == "table", n.id
    cubes = sorted(n.id for n in fused.nodes if n.category == "cube")
    assert cubes == ["cube_1", "cube_2", "cube_3", "cube_4"]
    assert sorted(n.id for n in fused.nodes if n.category == "cube") == sorted(
        n.id for n in single.nodes if n.category == "cube"
    )  # the second camera's cubes merged, not duplicated
    assert all(n.attributes["views"] == 2 for n in fused.nodes if n.category == "cube")
    drawers = {n.id: n for n in fused.nodes if n.category == "drawer"}
    assert set(drawers) == {"cabinet_1/drawer_1", "cabinet_1/drawer_2"}
    assert {n.parent for n in drawers.values()} == {"cabinet_1"}
    assert sorted(n.attributes["level"] for n in drawers.values()) == [0, 1]


def test_relations_through_the_overlap_matching(rendered):
    from gsr.benchmarks.perception.eval import as_truth_ids

    frames_, truth = rendered
    graph, _ = perceive_rgbd(_views(frames_), SegmentationDetector(frames_))
    truth = _with_boxes(truth, frames_)
    matching = match_nodes(graph, truth)
    scored = NodeScore()
    scored.add(graph, truth, matching)
    renamed = as_truth_ids(graph, matching)
    support = lambda g: {e.key() for e in g.edges if e.relation in ("on", "in")}  # noqa: E731
    want = {e for e in support(truth) if not e[0].startswith("table")}
    got = support(renamed)
    assert len(want & got) >= len(want) - 1, (want - got, got - want)
    # colours come from the pixels; categories from the (perfect) detector
    assert scored.to_dict()["recall"] >= 0.8


def _with_boxes(truth: SceneGraph, frames_) -> SceneGraph:
    """The procedural truth has no boxes: take them from the labelled points (what the eval's truth has)."""
    from gsr.perception.pipeline import perceive

    boxes = {n.id: n for n in perceive(frames_).nodes}
    return truth.with_nodes(
        n.model_copy(update={"bbox": boxes[n.id].bbox, "pose": boxes[n.id].pose})
        for n in truth.nodes
        if n.id in boxes
    )


def _node(nid: str, cat: str, x: float, y: float, color: str = "red", parent: str | None = None) -> Node:
    half = 0.02
    return Node(
        id=nid,
        category=cat,
        parent=parent,
        attributes={"color": color, "size_x": 0.04, "size_y": 0.04, "size_z": 0.04},
        bbox=BoundingBox(min=Vec3(x=x - half, y=y - half, z=0.0), max=Vec3(x=x + half, y=y + half, z=0.04)),
    )


def test_tracker_keeps_ids_of_objects_that_stay_and_that_move():
    t = Tracker()
    first = t.assign(
        SceneGraph(nodes=(_node("cube_1", "cube", 0.5, 0.0), _node("cube_2", "cube", 0.5, 0.3, "blue"))), None
    )
    assert {n.id for n in first.nodes} == {"cube_1", "cube_2"}
    # perception numbers the next observation afresh: the blue cube (moved 40 cm) comes first now
    second = SceneGraph(
        nodes=(
            _node("cube_1", "cube", 0.9, -0.2, "blue"),
            _node("cube_2", "cube", 0.51, 0.0),
            _node("bowl_1", "bowl", 0.3, 0.3, "white"),
        )
    )
    tracked = t.assign(second, first).node_map()
    assert tracked["cube_2"].attributes["color"] == "blue"  # moved: kept its id by appearance
    assert tracked["cube_1"].attributes["color"] == "red"  # stayed: kept its id by place
    assert "bowl_1" in tracked
    # an id once issued is never reused for another object
    third = t.assign(SceneGraph(nodes=(_node("cube_1", "cube", 0.1, 0.5, "green"),)), SceneGraph(nodes=()))
    assert [n.id for n in third.nodes] == ["cube_3"]


def test_tracker_parts_follow_parent_and_level():
    t = Tracker()
    cab = _node("cabinet_1", "cabinet", 1.0, 0.0, "white")
    low = _node("cabinet_1/drawer_1", "drawer", 0.9, 0.0, "white", parent="cabinet_1")
    low = low.model_copy(update={"attributes": {**low.attributes, "level": 0}})
    first = t.assign(SceneGraph(nodes=(cab, low)), None)
    moved = low.model_copy(update={"id": "cabinet_2/drawer_1", "parent": "cabinet_2"})
    second = t.assign(SceneGraph(nodes=(cab.model_copy(update={"id": "cabinet_2"}), moved)), first)
    assert {n.id for n in second.nodes} == {"cabinet_1", "cabinet_1/drawer_1"}


def test_rename_graph_renames_edges_and_parents():
    g = SceneGraph(nodes=(_node("a_1", "cube", 0, 0), _node("b_1", "plate", 0, 0)))
    assert {n.id for n in rename_graph(g, {"a_1": "x_1"}).nodes} == {"x_1", "b_1"}


def test_bad_input_is_one_line_or_an_empty_graph(rendered):
    frames_, _ = rendered
    f = frames_[0]
    with pytest.raises(GSRError, match="no depth image"):
        check_view(f.rgb, None, f.camera)
    with pytest.raises(GSRError, match="sizes differ"):
        check_view(f.rgb, f.depth[:-2], f.camera)
    with pytest.raises(GSRError, match="HxWx3"):
        check_view(f.rgb[..., 0], f.depth, f.camera)
    nan = f.depth.copy()
    nan[:100] = np.nan
    view = check_view(f.rgb, nan, f.camera)
    assert np.isfinite(view.depth).all() and (view.depth[:100] == 0).all()
    empty = check_view(f.rgb, np.zeros_like(f.depth), f.camera)
    graph, _ = perceive_rgbd([empty], SegmentationDetector(frames_), timing=Timing())
    assert graph.nodes == ()
    all_nan = check_view(f.rgb, np.full_like(f.depth, np.nan), f.camera)
    graph, _ = perceive_rgbd([all_nan], SegmentationDetector(frames_))
    assert graph.nodes == ()
    with pytest.raises(GSRError, match="mask 0"):
        frame_from_detections(
            View(f.rgb, f.depth, f.camera), [Det(mask=np.ones((3, 3), bool), category="cube")]
        )


def test_overlapping_detections_go_to_the_higher_score(rendered):
    frames_, _ = rendered
    f = frames_[0]
    a = np.zeros(f.depth.shape, bool)
    a[100:200, 100:200] = True
    b = np.zeros_like(a)
    b[150:250, 150:250] = True
    frame = frame_from_detections(
        View(f.rgb, f.depth, f.camera), [Det(a, "cube", 0.9, "red"), Det(b, "bowl", 0.5, "blue")]
    )
    assert frame.labels[frame.masks[160, 160]].category == "cube"
    assert frame.labels[frame.masks[240, 240]].category == "bowl"
    assert all(lab.id is None for lab in frame.labels.values())


def _inst(key: str, category: str, lo, hi, parent: str | None = None, views: int = 1):
    from gsr.perception.frame import InstanceLabel
    from gsr.perception.geometry import Instance, fit_boxes

    rng = np.random.default_rng(0)
    pts = rng.uniform(lo, hi, size=(400, 3))
    inst = Instance(
        key, InstanceLabel(category=category, parent=parent), pts, np.full((400, 3), 128, np.uint8), views
    )
    fit_boxes(inst)
    return inst


def test_ground_pieces_of_one_view_are_one_ground_and_spanning_parts_are_dropped():
    from gsr.perception.geometry import GeometryParams
    from gsr.perception.track import fuse_views, spanning_parts

    left = _inst("table_f0m0", "table", (0.0, -0.5, -0.01), (0.4, 0.0, 0.0))
    right = _inst("table_f0m1", "table", (0.0, 0.05, -0.01), (0.4, 0.5, 0.0))
    shelf = _inst("table_f1m0", "table", (0.0, -0.5, 0.3), (0.4, 0.5, 0.31))  # another height: another ground
    fused = fuse_views([left, right, shelf], GeometryParams(voxel=0))
    assert sorted(len(f.points) for f in fused) == [400, 800]
    low = _inst("d1", "drawer", (0.0, 0.0, 0.0), (0.1, 0.3, 0.1), parent="cab", views=2)
    high = _inst("d2", "drawer", (0.0, 0.0, 0.11), (0.1, 0.3, 0.2), parent="cab", views=2)
    both = _inst("d3", "drawer", (0.0, 0.0, 0.0), (0.1, 0.3, 0.2), parent="cab")
    assert spanning_parts([low, high, both]) == {id(both)}
    assert spanning_parts([low, both]) == set()  # one part inside is no evidence of a merge


def test_a_part_follows_the_detectors_parent_link_over_the_box_rule():
    import dataclasses

    from gsr.perception.geometry import GeometryParams
    from gsr.perception.track import assign_parts, fuse_views

    cabinet = _inst("cabinet_f0m0", "cabinet", (0.0, 0.0, 0.0), (0.3, 0.4, 0.4))
    big = _inst("stove_f0m1", "stove", (-0.1, -0.1, 0.0), (0.5, 0.6, 0.5))  # holds the drawer's box too
    drawer = _inst("drawer_f0m2", "drawer", (0.25, 0.05, 0.1), (0.3, 0.35, 0.2))
    drawer.label = dataclasses.replace(drawer.label, parent=None, attributes={"parent_detection": 0})
    fused = fuse_views([cabinet, big, drawer], GeometryParams(voxel=0))
    assign_parts(fused)
    part = next(i for i in fused if i.label.category == "drawer")
    owner = next(i for i in fused if i.label.category == "cabinet" and i.aabb_max[2] < 0.45)
    assert part.label.parent == owner.key and part.key == f"{owner.key}/drawer_1"
    assert all(not k.startswith("_") and k != "parent_detection" for i in fused for k in i.label.attributes)
