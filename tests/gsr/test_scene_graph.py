"""SceneGraph model: JSON round trip (property-based), validation errors naming the field, text and diff."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gsr.errors import GSRError
from gsr.graph_diff import diff_graphs
from gsr.graph_text import to_prompt_text
from gsr.scene_graph import RELATIONS, BoundingBox, Edge, Node, Pose, SceneGraph, Vec3

_names = st.from_regex(r"[a-z][a-z0-9_]{0,8}", fullmatch=True)
_coord = st.floats(min_value=-5, max_value=5, allow_nan=False, allow_infinity=False)
_attr_value = st.one_of(
    st.sampled_from(["red", "blue", "wooden"]),
    st.integers(-3, 3),
    st.booleans(),
    st.floats(-1, 1, allow_nan=False),
)


@st.composite
def scene_graphs(draw: st.DrawFn) -> SceneGraph:
    """Random valid graphs: unique ids, parts under earlier nodes, edges between distinct nodes."""
    ids = draw(st.lists(_names, min_size=1, max_size=8, unique=True))
    nodes: list[Node] = []
    for i, node_id in enumerate(ids):
        parent = draw(st.one_of(st.none(), st.sampled_from(ids[:i]))) if i else None
        full_id = f"{parent}/{node_id}" if parent else node_id
        pose = None
        if draw(st.booleans()):
            pose = Pose(position=Vec3(x=draw(_coord), y=draw(_coord), z=draw(_coord)))
        bbox = None
        if draw(st.booleans()):
            lo = Vec3(x=draw(_coord), y=draw(_coord), z=draw(_coord))
            bbox = BoundingBox(min=lo, max=Vec3(x=lo.x + 1, y=lo.y + 1, z=lo.z + 1))
        nodes.append(
            Node(
                id=full_id,
                category=draw(st.sampled_from(["cube", "box", "drawer", "table", "thing"])),
                attributes=draw(
                    st.dictionaries(
                        st.sampled_from(["color", "level", "size", "lid"]), _attr_value, max_size=3
                    )
                ),
                states=tuple(
                    draw(st.lists(st.sampled_from(["open", "closed", "on", "off", "held"]), max_size=2))
                ),
                parent=parent,
                pose=pose,
                bbox=bbox,
            )
        )
        ids[i] = full_id
    edges: dict[tuple[str, str, str], Edge] = {}
    if len(ids) > 1:
        for _ in range(draw(st.integers(0, 10))):
            s, t = draw(st.lists(st.sampled_from(ids), min_size=2, max_size=2, unique=True))
            e = Edge(source=s, relation=draw(st.sampled_from(RELATIONS)), target=t)
            edges[e.key()] = e
    return SceneGraph(
        nodes=tuple(nodes), edges=tuple(edges.values()), metadata={"seed": draw(st.integers(0, 9))}
    )


@settings(max_examples=60, deadline=None)
@given(scene_graphs())
def test_json_round_trip(graph: SceneGraph) -> None:
    back = SceneGraph.from_json(graph.to_json())
    assert back == graph
    assert SceneGraph.from_json(graph.to_json(indent=None)) == graph


@settings(max_examples=30, deadline=None)
@given(scene_graphs())
def test_prompt_text_is_deterministic_and_mentions_every_edge(graph: SceneGraph) -> None:
    text = to_prompt_text(graph)
    assert text == to_prompt_text(SceneGraph.from_json(graph.to_json()))
    for e in graph.edges:
        assert f"{e.source} {e.relation.replace('_', ' ')} {e.target}" in text


@settings(max_examples=30, deadline=None)
@given(scene_graphs(), scene_graphs())
def test_diff_empty_iff_equal_up_to_edge_order(a: SceneGraph, b: SceneGraph) -> None:
    assert diff_graphs(a, a).is_empty
    shuffled = a.with_edges(reversed(a.edges))
    assert diff_graphs(a, shuffled).is_empty
    d = diff_graphs(a, b)
    same = {n.id: (n.category, n.parent, set(n.states), n.attributes) for n in a.nodes} == {
        n.id: (n.category, n.parent, set(n.states), n.attributes) for n in b.nodes
    } and {e.key() for e in a.edges} == {e.key() for e in b.edges}
    assert d.is_empty == same
    json.dumps(d.to_dict())  # JSON-ready


def _data(nodes: list[dict], edges: list[dict]) -> dict:
    return {"nodes": nodes, "edges": edges}


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        (_data([{"id": "a", "category": "cube"}], [{"source": "a", "relation": "on", "target": "b"}]), "'b'"),
        (
            _data([{"id": "a", "category": "cube"}, {"id": "a", "category": "box"}], []),
            "duplicate node id 'a'",
        ),
        (
            _data(
                [{"id": "a", "category": "cube"}, {"id": "b", "category": "box"}],
                [{"source": "a", "relation": "inside_of", "target": "b"}],
            ),
            "edges.0.relation",
        ),
        (_data([{"id": "9a", "category": "cube"}], []), "nodes.0.id"),
        (_data([{"id": "a", "category": "cube", "parent": "zz"}], []), "parent 'zz'"),
        (_data([{"id": "a"}], []), "nodes.0.category"),
    ],
)
def test_invalid_graphs_name_the_problem(data: dict, needle: str) -> None:
    with pytest.raises(GSRError) as info:
        SceneGraph.from_data(data, "scene.json")
    assert "scene.json" in str(info.value)
    assert needle in str(info.value)


def test_invalid_json_reports_line_and_column() -> None:
    with pytest.raises(GSRError, match=r"x.json:2:\d+: invalid JSON"):
        SceneGraph.from_json('{"nodes": [\n  oops]}', "x.json")


def test_prompt_text_nests_parts_and_states() -> None:
    g = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="red_cube1", category="cube", attributes={"color": "red"}),
            Node(id="short_cabinet", category="cabinet"),
            Node(
                id="short_cabinet/drawer_low", category="drawer", parent="short_cabinet", states=("closed",)
            ),
        ),
        edges=(Edge(source="red_cube1", relation="on", target="table"),),
    )
    assert to_prompt_text(g) == (
        "objects: table (table); red_cube1 (cube, red); short_cabinet (cabinet) parts: drawer_low (drawer) [closed]\n"
        "relations: red_cube1 on table"
    )
    assert "drawer_low [closed]" in to_prompt_text(g, terse=True)


def test_diff_reports_moves_and_state_changes() -> None:
    a = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="cube", category="cube"),
            Node(id="box", category="lidded_box", states=("closed",)),
        ),
        edges=(Edge(source="cube", relation="on", target="table"),),
    )
    b = a.with_nodes([Node(id="box", category="lidded_box", states=("open",))]).with_edges(
        [Edge(source="cube", relation="in", target="box")]
    )
    d = diff_graphs(a, b)
    assert d.added_edges == (("cube", "in", "box"),)
    assert d.removed_edges == (("cube", "on", "table"),)
    assert d.state_changes == {"box": (("closed",), ("open",))}
    assert str(d).splitlines() == ["- cube on table", "+ cube in box", "~ box: closed -> open"]
    assert d.to_dict()["state_changes"] == {"box": {"removed": ["closed"], "added": ["open"]}}


def test_support_is_the_on_or_in_edge_and_none_for_roots_and_parts() -> None:
    g = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="cabinet", category="cabinet"),
            Node(id="cabinet/drawer", category="drawer", parent="cabinet"),
            Node(id="bowl", category="bowl"),
            Node(id="cube", category="cube"),
        ),
        edges=(
            Edge(source="cabinet", relation="on", target="table"),
            Edge(source="bowl", relation="in", target="cabinet/drawer"),
            Edge(source="cube", relation="near", target="bowl"),
        ),
    )
    assert g.support("bowl") == Edge(source="bowl", relation="in", target="cabinet/drawer")
    assert g.support("cabinet").target == "table"
    assert g.support("table") is None and g.support("cabinet/drawer") is None
    assert g.support("cube") is None  # "near" holds nothing up
    assert g.supports() == {"cabinet": g.support("cabinet"), "bowl": g.support("bowl")}
