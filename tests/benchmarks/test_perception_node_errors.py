"""Node errors sorted by kind (gsr.benchmarks.perception.node_errors.classify_errors) on hand-built graphs."""

from __future__ import annotations

from gsr.benchmarks.perception.node_errors import classify_errors

from gsr.scene_graph import BoundingBox, Node, Pose, SceneGraph, Vec3


def _node(node_id: str, category: str, lo, hi, color: str | None = None, parent: str | None = None) -> Node:
    centre = Vec3(x=(lo[0] + hi[0]) / 2, y=(lo[1] + hi[1]) / 2, z=(lo[2] + hi[2]) / 2)
    return Node(
        id=node_id,
        category=category,
        parent=parent,
        attributes={"color": color} if color else {},
        pose=Pose(position=centre),
        bbox=BoundingBox(min=Vec3(x=lo[0], y=lo[1], z=lo[2]), max=Vec3(x=hi[0], y=hi[1], z=hi[2])),
    )


def test_errors_are_sorted_into_missed_false_category_and_colour():
    truth = SceneGraph(
        nodes=(
            _node("cabinet", "cabinet", (0.0, 0.0, 0.0), (0.3, 0.3, 0.3)),
            _node("red_cube", "cube", (0.5, 0.0, 0.0), (0.54, 0.04, 0.04), "red"),
            _node("blue_mug", "mug", (0.7, 0.0, 0.0), (0.78, 0.08, 0.09), "blue"),
            _node("yellow_cube", "cube", (0.5, 0.5, 0.0), (0.54, 0.54, 0.04), "yellow"),
            _node("hidden_cube", "cube", (0.1, 0.1, 0.05), (0.14, 0.14, 0.09), "red"),
            _node("far_cube", "cube", (-0.5, -0.5, 0.0), (-0.46, -0.46, 0.04), "blue"),
        )
    )
    perceived = SceneGraph(
        nodes=(
            _node("cabinet_1", "cabinet", (0.0, 0.0, 0.0), (0.3, 0.3, 0.3)),
            _node("cabinet_2", "cabinet", (0.28, 0.05, 0.1), (0.3, 0.1, 0.2)),  # a strip of its wall
            _node("cube_1", "cube", (0.5, 0.0, 0.0), (0.54, 0.04, 0.04), "red"),  # right
            _node("mug_1", "mug", (0.7, 0.0, 0.0), (0.78, 0.08, 0.09), "red"),  # wrong colour
            _node("mug_2", "mug", (0.5, 0.5, 0.0), (0.54, 0.54, 0.04), "yellow"),  # wrong category
            _node("box_1", "box", (2.0, 2.0, 0.0), (2.1, 2.1, 0.1), "red"),  # nothing there
        )
    )
    visible = {"cabinet", "red_cube", "blue_mug", "yellow_cube", "far_cube"}
    errors = classify_errors(perceived, truth, visible)
    kinds = sorted((e["kind"], e["sub"], e["truth"]) for e in errors)
    assert kinds == [
        ("category", "", "cube/yellow"),
        ("colour", "", "mug/blue"),
        ("false", "duplicate", "cabinet/-"),
        ("false", "spurious", "-"),
        ("missed", "hidden", "cube/red"),
        ("missed", "seen", "cube/blue"),
    ]
