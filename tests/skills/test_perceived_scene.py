"""The perception-backed graph source's graph rules: map regions, the gripper, unsensed states, what is compared."""

from __future__ import annotations

import re
from contextlib import contextmanager
from dataclasses import dataclass, field

import pytest

pytest.importorskip(
    "pybullet"
)  # observable_view uses gsr.skills.executor.symbolic_view (skills imports pybullet)

from gsr.skills.perceived_scene import (
    contradicted_effects,
    observable_view,
    observed_ids,
    with_held,
    with_map_regions,
    with_unsensed_states,
)

from gsr.graph_diff import diff_graphs
from gsr.scene_graph import Edge, Node, Pose, SceneGraph, Vec3


def _node(nid: str, category: str, x: float = 0.0, y: float = 0.0, **kw) -> Node:
    pose = Pose(position=Vec3(x=x, y=y, z=0.8), orientation=(0.0, 0.0, 0.0, 1.0))
    return Node(id=nid, category=category, pose=pose, **kw)


def _graph(nodes: list[Node], edges: list[tuple[str, str, str]]) -> SceneGraph:
    return SceneGraph(
        nodes=tuple(nodes), edges=tuple(Edge(source=a, relation=r, target=b) for a, r, b in edges)
    )


@dataclass
class _Region:
    bounds: tuple[float, float, float, float]


@dataclass
class _MapWorld:
    """What with_map_regions reads of a skills World: the task graph, the table id, the region map."""

    graph: SceneGraph
    table_id: str = "table"
    regions: dict[str, _Region] = field(default_factory=dict)


def test_objects_on_the_table_inside_a_region_are_on_the_region() -> None:
    region = Node(id="table/front_region", category="region", parent="table")
    truth = _graph([_node("table", "table"), region], [])
    world = _MapWorld(truth, regions={"table/front_region": _Region((0.0, 0.0, 0.2, 0.2))})
    seen = _graph(
        [_node("table", "table"), _node("plate", "plate", 0.1, 0.1), _node("cup", "cup", 0.5, 0.5)],
        [("plate", "on", "table"), ("cup", "on", "table")],
    )
    out = with_map_regions(seen, world)
    edges = {e.key() for e in out.edges}
    assert ("plate", "on", "table/front_region") in edges and ("cup", "on", "table") in edges
    assert out.node("table/front_region").attributes["map"] is True
    assert "table/front_region" not in observed_ids(out)  # a map node is not an observation
    assert with_map_regions(seen, _MapWorld(truth)) == seen  # no regions: unchanged


def test_an_object_standing_on_a_regions_edge_keeps_its_region_or_the_table() -> None:
    from gsr.scene_graph import BoundingBox

    region = Node(id="table/front_region", category="region", parent="table")
    world = _MapWorld(
        _graph([_node("table", "table"), region], []),
        regions={"table/front_region": _Region((0.0, 0.17, 0.2, 0.25))},
    )

    def seen(y: float) -> SceneGraph:  # a 4 cm cheese box whose measured centre is at y
        box = BoundingBox(min=Vec3(x=0.08, y=y - 0.02, z=0.8), max=Vec3(x=0.12, y=y + 0.02, z=0.85))
        cheese = _node("cheese", "cream_cheese", 0.1, y, bbox=box)
        return _graph([_node("table", "table"), cheese], [("cheese", "on", "table")])

    first = with_map_regions(seen(0.1705), world)
    assert ("cheese", "on", "table/front_region") in {e.key() for e in first.edges}
    # the arm hides part of it: the measured centre moves 1 mm past the edge; it has not moved
    again = with_map_regions(seen(0.1695), world, previous=first)
    assert ("cheese", "on", "table/front_region") in {e.key() for e in again.edges}
    # without the belief the centre rule alone decides; moved off, its box leaves the region
    assert ("cheese", "on", "table") in {e.key() for e in with_map_regions(seen(0.1695), world).edges}
    gone = with_map_regions(seen(0.12), world, previous=first)
    assert ("cheese", "on", "table") in {e.key() for e in gone.edges}
    # the other way round: seen first just off the region, then 1 mm inside it, it stays on the table
    off = with_map_regions(seen(0.1695), world)
    inside = with_map_regions(seen(0.1705), world, previous=off)
    assert ("cheese", "on", "table") in {e.key() for e in inside.edges}
    # pushed well into the region (moved), it is on the region even though its box was outside before
    pushed = with_map_regions(seen(0.2), world, previous=off)
    assert ("cheese", "on", "table/front_region") in {e.key() for e in pushed.edges}


def test_held_objects_come_from_the_gripper_and_lose_their_support() -> None:
    seen = _graph([_node("table", "table"), _node("cup", "cup")], [("cup", "on", "table")])
    out = with_held(seen, {"cup"}, None)
    assert "held" in out.node("cup").states and not out.edges
    # the hand hides the cup from every camera: its node comes from the last belief
    belief = out
    hidden = _graph([_node("table", "table")], [])
    again = with_held(hidden, {"cup"}, belief)
    assert again.has_node("cup") and "held" in again.node("cup").states
    assert "cup" in observed_ids(again)  # the gripper confirms what it holds
    assert with_held(seen, set(), None) is seen


def test_power_states_are_carried_from_the_prior_not_perceived() -> None:
    prior = _graph([_node("stove", "stove", states=("on",)), _node("lamp", "lamp")], [])
    seen = _graph([_node("stove", "stove"), _node("lamp", "lamp", states=("on",))], [])
    out = with_unsensed_states(seen, prior)
    assert out.node("stove").states == ("on",)  # no camera shows a stove is on: the prior's value
    assert out.node("lamp").states == ()  # and no camera can claim it is on either
    assert with_unsensed_states(seen, None) is seen


def test_observable_view_compares_only_what_sensors_confirm() -> None:
    expected = _graph(
        [
            _node("table", "table"),
            _node("cup", "cup", attributes={"points": 10}),
            _node("stove", "stove", states=("on",)),
            _node("drawer", "drawer", states=("open",)),
            _node("bowl", "bowl", attributes={"observed": False}),
        ],
        [("cup", "on", "table"), ("bowl", "in", "drawer")],
    )
    observed = _graph(
        [
            _node("table", "table"),
            _node("cup", "cup", attributes={"points": 99}),  # geometry differs: not a divergence
            _node("stove", "stove"),  # power unseen: not a divergence
            _node("drawer", "drawer", states=("open",)),
        ],
        [("cup", "on", "table")],
    )
    confirmed = observed_ids(observed)
    assert diff_graphs(observable_view(expected, confirmed), observable_view(observed, confirmed)).is_empty
    moved = observed.model_copy(
        update={"edges": (Edge(source="cup", relation="on", target="drawer"),)}
    )  # the cup is somewhere else: that is a divergence
    diff = diff_graphs(observable_view(expected, confirmed), observable_view(moved, confirmed))
    assert not diff.is_empty and "cup" in str(diff)
    shut = observed.model_copy(update={"nodes": (*observed.nodes[:3], _node("drawer", "drawer"))})
    assert not diff_graphs(
        observable_view(expected, confirmed), observable_view(shut, observed_ids(shut))
    ).is_empty


def test_observable_view_keeps_the_object_of_a_confirmed_part() -> None:
    # a sensor confirms a drawer (open) but not its rack: the rack stays as a bare node, or the
    # drawer's parent would dangle (this raised pydantic's "parent ... is not a node")
    rack = _node("rack_3", "rack", states=("open",))
    drawer = Node(id="rack_3/drawer_3", category="drawer", parent="rack_3", states=("open",))
    graph = _graph([_node("table", "table"), rack, drawer], [("rack_3", "on", "table")])
    view = observable_view(graph, {"rack_3/drawer_3"})
    assert {n.id for n in view.nodes} == {"rack_3", "rack_3/drawer_3"}
    assert view.node("rack_3").states == () and view.node("rack_3/drawer_3").states == ("open",)
    assert view.edges == ()  # the rack's own support is not confirmed


def test_contradicted_effects_ignore_unobservable_predicates() -> None:
    from gsr.check import check_step
    from gsr.facts import state_from_graph
    from gsr.resources import load_builtin_domain
    from gsr.step import Step

    domain = load_builtin_domain("tabletop")
    graph = _graph([_node("table", "table"), _node("stove", "stove")], [("stove", "on", "table")])
    diagnosis = check_step(domain, state_from_graph(graph, domain), Step(action="turn_on", args=("stove",)))
    assert diagnosis.ok, diagnosis.message
    assert contradicted_effects(diagnosis, graph, domain) == []  # turned_on is not camera-observable


@contextmanager
def _libero10_world(libero_dir, scene: str):
    """A built world (seed 0) of a LIBERO-10 task, closed afterwards."""
    from gsr.benchmarks.suites.libero_suite import task_from_bddl
    from gsr.skills import build_world

    world = build_world(task_from_bddl(libero_dir / "libero_10" / f"{scene}.bddl"), seed=0)
    try:
        yield world
    finally:
        world.close()


def _perception_id(node) -> bool:
    """The id perception gives a node it found: ``category_k``, under its parent for a part."""
    own = re.escape(node.category) + r"_\d+"
    return bool(re.fullmatch(rf"(?:.+/)?{own}", node.id))


BOWL_IN_DRAWER = "KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it"


@pytest.mark.physics
def test_perceived_scene_in_a_real_world(libero_dir) -> None:
    """Held from the gripper, regions from the map, a bowl in a closed drawer remembered."""
    pytest.importorskip("open3d")
    from gsr.skills import run_step
    from gsr.skills.perceived_scene import PerceivedScene

    from gsr.step import Step

    with _libero10_world(libero_dir, BOWL_IN_DRAWER) as world:
        scene = PerceivedScene(world, oracle_masks=True)
        first = scene.observe()
        assert first.metadata["source"] == "perception" and scene.last_rgb is not None
        bowl, drawer = "akita_black_bowl_1", "white_cabinet_1/bottom_drawer"
        support = next(e.target for e in first.edges if e.source == bowl and e.relation == "on")
        assert run_step(world, Step("pick", (bowl, support))).ok
        held = scene.observe()
        assert "held" in held.node(bowl).states
        assert not [e for e in held.edges if e.source == bowl and e.relation in ("on", "in")]
        assert run_step(world, Step("place_in", (bowl, drawer))).ok
        assert ("akita_black_bowl_1", "in", drawer) in {e.key() for e in scene.observe().edges}
        assert run_step(world, Step("close", (drawer,))).ok
        closed = scene.observe()
        assert closed.node(bowl).attributes["observed"] is False  # hidden by the closed drawer
        assert (bowl, "in", drawer) in {e.key() for e in closed.edges}
        assert bowl not in observed_ids(closed) and scene.observations == 4


@pytest.mark.physics
def test_a_door_without_a_part_node_is_segmented_and_measured(libero_dir) -> None:
    """The microwave's door is no graph node: its own mask lets perception see it open or closed."""
    pytest.importorskip("open3d")
    import pybullet as p
    from gsr.skills.perceived_scene import PerceivedScene

    scene_name = "KITCHEN_SCENE6_put_the_yellow_and_white_mug_in_the_microwave_and_close_it"
    with _libero10_world(libero_dir, scene_name) as world:
        scene = PerceivedScene(world, oracle_masks=True)
        door = world.objects["microwave_1"]
        labels = {lab.id for f in scene.frames() for lab in f.labels.values()}
        assert "microwave_1/door" in labels  # a mask of its own
        for q, state in ((0.0, "closed"), (1.5, "open"), (0.3, "closed")):
            p.resetJointState(door.body, door.links["door"], q, physicsClientId=world.client)
            graph = scene.observe()
            assert state in graph.node("microwave_1").states, (q, graph.node("microwave_1").states)
            assert not graph.has_node("microwave_1/door")  # the helper node is not in the agent's graph


def test_a_released_object_no_camera_sees_is_where_the_step_put_it() -> None:
    from gsr.skills.perceived_scene import with_remembered_support

    # the cube was held; now nobody sees it (remembered from the last belief, grasp state and all)
    belief = _graph(
        [
            _node("table", "table"),
            _node("box", "box"),
            _node("cube", "cube", states=("held",), attributes={"observed": False}),
        ],
        [("box", "on", "table")],
    )
    expected = _graph(
        [_node("table", "table"), _node("box", "box"), _node("cube", "cube")],
        [("box", "on", "table"), ("cube", "in", "box")],
    )
    out = with_remembered_support(belief, set(), expected)
    assert "held" not in out.node("cube").states  # the gripper no longer holds it
    assert ("cube", "in", "box") in {e.key() for e in out.edges}  # the step's own effect
    still = with_remembered_support(belief, {"cube"}, expected)
    assert "held" in still.node("cube").states and not [e for e in still.edges if e.source == "cube"]
    seen = belief.model_copy(update={"nodes": (*belief.nodes[:2], _node("cube", "cube"))})
    assert with_remembered_support(seen, set(), expected) is seen  # seen nodes keep what was seen


@pytest.mark.physics
def test_no_oracle_scene_keeps_ids_binds_bodies_and_tracks_a_grasp(libero_dir) -> None:
    """Without the simulator's masks: perception's own ids, stable across observations, bound to bodies."""
    pytest.importorskip("open3d")
    from gsr.skills import run_step
    from gsr.skills.perceived_scene import PerceivedScene

    from gsr.step import Step

    with _libero10_world(libero_dir, BOWL_IN_DRAWER) as world:
        scene = PerceivedScene(world)
        first = scene.observe()
        world_ids = {n.id for n in world.graph.nodes}
        seen = [n for n in first.nodes if not n.attributes.get("map")]
        # perception names what it sees itself (category_k, parts parent/category_k); a LIBERO id such as
        # wine_bottle_1 may follow the same scheme by chance, so the check is the scheme, not disjointness
        assert seen and all(_perception_id(n) for n in seen), [n.id for n in seen]
        assert {n.id for n in seen} - world_ids  # not the task graph's ids under another name
        again = scene.observe()
        assert {n.id for n in seen} <= {n.id for n in again.nodes}  # nothing moved: the same ids
        bowl = next(p for p, w in scene.binding.items() if w == "akita_black_bowl_1")
        support = next(e.target for e in first.edges if e.source == bowl and e.relation == "on")
        assert scene.world_id(support) in {world.table_id, *world.regions}
        assert run_step(world, Step("pick", ("akita_black_bowl_1", world.table_id))).ok
        held = scene.observe()
        in_hand = next(p for p, w in scene.binding.items() if w == "akita_black_bowl_1")
        assert "held" in held.node(in_hand).states  # the gripper's grasp, on the perceived node it is
        assert not [e for e in held.edges if e.source == in_hand and e.relation in ("on", "in")]
        assert "held" in scene.in_world_ids(held).node("akita_black_bowl_1").states


def test_a_part_of_a_seen_object_stays_when_the_cameras_do_not_pick_it_out() -> None:
    from gsr.skills.perceived_scene import with_unseen_parts

    cab = _node("cabinet_1", "cabinet")
    drawer = _node("cabinet_1/drawer_1", "drawer", parent="cabinet_1", states=("open",))
    belief = _graph([cab, drawer, _node("bowl_1", "bowl")], [("bowl_1", "in", "cabinet_1/drawer_1")])
    expected = _graph([cab, drawer.model_copy(update={"states": ("closed",)})], [])
    now = _graph([cab], [])  # the drawer was pushed shut: flush, no segment of its own
    out = with_unseen_parts(now, belief, expected).node_map()
    assert out["cabinet_1/drawer_1"].states == ("closed",)  # the robot's own step, not a sensor
    assert out["cabinet_1/drawer_1"].attributes["observed"] is False
    assert "bowl_1" not in out  # objects are update_belief's business, not this rule's
    gone = with_unseen_parts(_graph([], []), belief, expected)
    assert not gone.nodes  # the cabinet itself is not seen: nothing is carried


def test_the_object_in_the_gripper_keeps_the_id_of_the_object_the_step_grasped() -> None:
    from gsr.skills.perceived_scene import PerceivedScene

    scene = PerceivedScene.__new__(PerceivedScene)  # no world needed for the rule itself
    scene.binding = {"bottle_1": "bbq_sauce", "mug_3": "bbq_sauce", "basket_1": "basket"}
    scene.belief = _graph([_node("bottle_1", "bottle", attributes={"color": "red"})], [])
    lifted = _graph([_node("mug_3", "mug", x=0.3), _node("basket_1", "basket")], [])  # renamed once lifted
    expected = _graph([_node("bottle_1", "bottle", states=("held",)), _node("basket_1", "basket")], [])
    graph, held = scene._keep_grasped_id(lifted, {"mug_3"}, expected)
    assert held == {"bottle_1"} and {n.id for n in graph.nodes} == {"bottle_1", "basket_1"}
    picked = graph.node("bottle_1")  # what it is from before the lift, where it is from now
    assert (
        picked.category == "bottle" and picked.attributes["color"] == "red" and picked.pose.position.x == 0.3
    )
    assert scene.binding["bottle_1"] == "bbq_sauce" and "mug_3" not in scene.binding
    # without the robot's own step, or when the grasped id is seen elsewhere, nothing is renamed
    assert scene._keep_grasped_id(lifted, {"mug_3"}, None) == (lifted, {"mug_3"})
    both = _graph([_node("mug_3", "mug"), _node("bottle_1", "bottle")], [])
    assert scene._keep_grasped_id(both, {"mug_3"}, expected) == (both, {"mug_3"})


def test_the_object_the_step_released_keeps_its_id_where_the_step_put_it() -> None:
    from gsr.skills.perceived_scene import PerceivedScene

    scene = PerceivedScene.__new__(PerceivedScene)  # no world needed for the rule itself
    cab = _node("cabinet_1", "cabinet")
    drawer = _node("cabinet_1/drawer_3", "drawer", parent="cabinet_1", states=("open",))
    scene.binding = {"bowl_1": "akita_black_bowl_1", "bowl_4": "akita_black_bowl_1", "milk_1": "cabinet"}
    scene.belief = _graph(
        [cab, drawer, _node("bowl_1", "bowl", states=("held",), attributes={"color": "black"})], []
    )
    expected = _graph([cab, drawer, _node("bowl_1", "bowl")], [("bowl_1", "in", "cabinet_1/drawer_3")])
    # in the drawer the bowl is read as another (white, smaller) bowl and a drawer wall as a milk carton
    seen = _graph(
        [cab, drawer, _node("bowl_4", "bowl", x=0.4, attributes={"color": "white"}), _node("milk_1", "milk")],
        [("bowl_4", "in", "cabinet_1/drawer_3"), ("milk_1", "in", "cabinet_1/drawer_3")],
    )
    graph = scene._keep_released_id(seen, set(), expected)
    bowl = graph.node("bowl_1")  # what it is from before, where it is from now
    assert (
        bowl.attributes["color"] == "black"
        and bowl.pose.position.x == 0.4
        and "bowl_4" not in graph.node_map()
    )
    assert any(e.source == "bowl_1" and e.relation == "in" for e in graph.edges)
    assert scene.binding["bowl_1"] == "akita_black_bowl_1" and "bowl_4" not in scene.binding
    # still held, not where the step put it, or two candidates: nothing is renamed
    assert scene._keep_released_id(seen, {"bowl_1"}, expected) == seen
    elsewhere = _graph([cab, drawer, _node("bowl_4", "bowl")], [])
    assert scene._keep_released_id(elsewhere, set(), expected) == elsewhere
    scene.belief = _graph([cab, drawer, _node("bowl_1", "bowl", states=("held",))], [])
    two = _graph(
        [cab, drawer, _node("bowl_4", "bowl"), _node("bowl_5", "bowl")],
        [("bowl_4", "in", "cabinet_1/drawer_3"), ("bowl_5", "in", "cabinet_1/drawer_3")],
    )
    assert scene._keep_released_id(two, set(), expected) == two
