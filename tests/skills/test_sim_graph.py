"""Ground-truth ``in``/``on`` of scene_graph_from_sim: the rim rule, stacks inside containers, tall contents."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from gsr.skills.build import build_world
from gsr.skills.sim_graph import container_volumes, graph_from_layout, interior_boxes, scene_graph_from_sim

from gsr.scene_graph import Edge, SceneGraph
from gsr.task_spec import Layout, PlacedObject


def _layout() -> tuple[Layout, SceneGraph]:
    objects = (
        # a box resting on the rim of a wider-mouthed box, with a cube inside the upper box
        PlacedObject(id="low_box", asset="box", position=(-0.2, 0.3, 0.0), color="blue"),
        PlacedObject(
            id="top_box", asset="box", position=(-0.2, 0.3, 0.0), size=(0.15, 0.15, 0.05), on="low_box"
        ),
        PlacedObject(id="cube", asset="cube", position=(-0.2, 0.3, 0.0), color="red", on="top_box"),
        # a cube on a cube in a tray: the upper one sticks out above the rim but rests on the tray's content
        PlacedObject(id="tray", asset="tray", position=(0.1, -0.3, 0.0), size=(0.22, 0.16, 0.05)),
        PlacedObject(id="c1", asset="cube", position=(0.1, -0.3, 0.0), size=(0.04, 0.04, 0.04), on="tray"),
        PlacedObject(id="c2", asset="cube", position=(0.1, -0.3, 0.0), size=(0.04, 0.04, 0.04), on="c1"),
        # a tall bottle in a basket: more than the basket's height, still in it
        PlacedObject(id="basket", asset="basket", position=(0.15, 0.3, 0.0)),
        PlacedObject(id="bottle", asset="bottle", position=(0.15, 0.3, 0.0), on="basket"),
    )
    layout = Layout(objects=objects, table_size=(0.9, 1.2))
    graph = graph_from_layout(layout)
    # the layout graph puts everything resting on a container *in* it; these two rest on top
    on_top = {("top_box", "low_box"), ("c2", "c1")}
    edges = tuple(
        Edge(source=e.source, relation="on", target=e.target) if (e.source, e.target) in on_top else e
        for e in graph.edges
    )
    return layout, SceneGraph(nodes=graph.nodes, edges=edges)


@pytest.mark.physics
def test_in_needs_the_object_inside_the_walls() -> None:
    layout, graph = _layout()
    with build_world(layout, seed=0, graph=graph) as w:
        truth = scene_graph_from_sim(w)
        vols = {v[0]: v for v in container_volumes(w)}
        assert [b[0] for b in interior_boxes(w)] == list(vols)  # same order, rims left out
        top_lo = w.body_aabb(w.objects["top_box"].body)[0]
    edges = {e.key() for e in truth.edges if e.relation in ("on", "in")}
    # the upper box overlaps the lower box's (1.5x tall) interior volume but sits on its rim
    _, _, hi, _, rim = vols["low_box"]
    assert hi[2] > rim + 0.03 and top_lo[2] >= rim - 0.01
    assert ("top_box", "on", "low_box") in edges
    assert ("cube", "in", "top_box") in edges
    assert ("c1", "in", "tray") in edges
    assert ("c2", "in", "tray") in edges  # above the rim, but resting on the tray's content
    assert ("bottle", "in", "basket") in edges
    assert ("basket", "on", "table") in edges and ("low_box", "on", "table") in edges
