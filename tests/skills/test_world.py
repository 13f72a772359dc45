"""World building and ground-truth scene graphs from simulator state."""

from __future__ import annotations

import numpy as np
import pytest
from gsr.skills.build import build_world
from gsr.skills.executor import symbolic_view
from gsr.skills.sim_graph import graph_from_layout, scene_graph_from_sim

from gsr.graph_diff import diff_graphs
from gsr.task_spec import Layout, PlacedObject


def test_ground_truth_matches_the_task_graph(bowl_world, bowl_task) -> None:
    observed = scene_graph_from_sim(bowl_world)
    assert {n.id for n in observed.nodes} == {n.id for n in bowl_task.initial.nodes}
    diff = diff_graphs(symbolic_view(bowl_task.initial), symbolic_view(observed))
    assert diff.is_empty, str(diff)
    bowl = observed.node("akita_black_bowl_1")
    assert bowl.pose is not None and bowl.bbox is not None
    drawer = observed.node("wooden_cabinet_1/top_drawer")
    assert "closed" in drawer.states
    assert any(k.name == "handle" for k in drawer.keypoints)


def test_parts_map_to_links(bowl_world) -> None:
    top = bowl_world.locate("wooden_cabinet_1/top_drawer")
    bottom = bowl_world.locate("wooden_cabinet_1/bottom_drawer")
    assert top.part == "drawer_2" and bottom.part == "drawer_0"
    assert top.body == bottom.body and top.link != bottom.link
    assert bowl_world.locate("wooden_cabinet_1/top_side").part == "top_side"


def test_link_owner_inverts_locate(bowl_world) -> None:
    """The one (body, link) -> node walk that masks and contacts share leads every node back to itself."""
    for oid in bowl_world.objects:
        loc = bowl_world.locate(oid)
        assert bowl_world.link_owner(loc.body, loc.link) == (oid, [])
    for nid in bowl_world.parts:
        loc = bowl_world.locate(nid)
        owner, parts = bowl_world.link_owner(loc.body, loc.link)
        assert owner == loc.object_id
        assert (nid in parts) is (loc.link >= 0), nid
    assert bowl_world.link_owner(bowl_world.table_body, -1) == (bowl_world.table_id, [])
    assert bowl_world.link_owner(bowl_world.robot.body, 3) is None


def test_build_is_deterministic_per_seed(bowl_task) -> None:
    def positions(seed: int) -> dict[str, tuple]:
        with build_world(bowl_task, seed=seed) as w:
            return {k: tuple(np.round(w.link_pose(o.body, -1)[0], 4)) for k, o in w.objects.items()}

    a, b, c = positions(3), positions(3), positions(4)
    assert a == b
    assert a != c


def test_layout_states_and_containment() -> None:
    layout = Layout(
        objects=(
            PlacedObject(
                id="cab",
                asset="cabinet",
                position=(0.15, 0.0, 0.0),
                fixed=True,
                joint_states={"drawer_1": 1.0},
            ),
            PlacedObject(id="box", asset="box", position=(-0.15, 0.2, 0.0), color="blue"),
            PlacedObject(id="red_cube", asset="cube", position=(-0.15, 0.2, 0.0), color="red", on="box"),
            PlacedObject(id="green_cube", asset="cube", position=(-0.15, -0.2, 0.0), color="green"),
        ),
        table_size=(0.9, 1.2),
    )
    graph = graph_from_layout(layout)
    with build_world(layout, seed=0, graph=graph) as w:
        g = scene_graph_from_sim(w)
    edges = {e.key() for e in g.edges}
    assert ("red_cube", "in", "box") in edges
    assert ("green_cube", "on", "table") in edges
    assert "open" in g.node("cab/drawer_1").states
    assert "closed" in g.node("cab/drawer_0").states


def test_unknown_support_is_a_clear_error() -> None:
    from gsr.errors import GSRError

    layout = Layout(objects=(PlacedObject(id="c", asset="cube", position=(0, 0, 0), on="nowhere"),))
    with pytest.raises(GSRError, match="nowhere"):
        build_world(layout, seed=0)
