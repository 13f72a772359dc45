"""GSR-Bench message format: generated and published configs load and write back; bad strings are named."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from gsr.errors import GSRError
from gsr.gsr_bench_format import graph_from_gsr_bench, gsr_bench_message, parse_edge, parse_node
from gsr.scene_graph import SceneGraph


@pytest.fixture(scope="module")
def configs(published_gsr_bench_file: Path) -> list[dict]:
    """The 90 published dev configs (skipped when absent)."""
    return yaml.safe_load(published_gsr_bench_file.read_text(encoding="utf-8"))["configs"]


def test_all_configs_round_trip(gsr_bench_style_configs: list[dict]) -> None:
    assert len(gsr_bench_style_configs) in (36, 90)  # generated 4 per cell, or the published dev file
    for cfg in gsr_bench_style_configs:
        message = cfg["scene_graph"]
        graph = graph_from_gsr_bench(message)
        back = gsr_bench_message(graph)
        assert back["nodes"] == list(message["nodes"]), cfg["number"]
        assert set(back["edges"]) == set(message["edges"]), cfg["number"]
        assert len(back["edges"]) == len(set(message["edges"]))
        # and through JSON
        assert SceneGraph.from_json(graph.to_json()) == graph


def test_config_with_drawers_gets_parts_levels_and_states(configs: list[dict]) -> None:
    cfg = next(c for c in configs if c["number"] == 107)
    g = graph_from_gsr_bench(cfg["scene_graph"])
    low = g.node("short_cabinet/drawer_low")
    assert (low.category, low.parent, low.states, low.attributes["level"]) == (
        "drawer",
        "short_cabinet",
        ("closed",),
        0,
    )
    assert g.node("short_cabinet/drawer_middle").attributes["level"] == 1
    assert g.node("short_cabinet/drawer_high").states == ("open",)
    assert g.node("short_cabinet/drawer_high").attributes["level"] == 2
    assert g.node("red_mug1").category == "mug"
    assert g.node("red_mug1").color == "red"
    assert g.node("porcelain_mug").category == "mug"
    assert g.node("milk").category == "milk"
    assert g.node("short_cabinet").category == "cabinet"
    assert [p.id for p in g.parts("short_cabinet")] == [
        "short_cabinet/drawer_low",
        "short_cabinet/drawer_middle",
        "short_cabinet/drawer_high",
    ]


def test_categories_and_colours_of_every_config_node(gsr_bench_style_configs: list[dict]) -> None:
    for cfg in gsr_bench_style_configs:
        g = graph_from_gsr_bench(cfg["scene_graph"])
        for n in g.nodes:
            assert n.category != "thing", n.id  # every GSR-Bench name maps to a real category
            if "cube" in n.id:
                assert n.category == "cube"
                assert n.color in ("red", "blue", "yellow")


def test_parse_node_and_edge() -> None:
    assert parse_node("short_cabinet/drawer_low(closed)") == ("short_cabinet/drawer_low", "closed")
    assert parse_node("table") == ("table", None)
    assert parse_edge("red_cube1(on)table") == ("red_cube1", "on", "table")
    # a state suffix on an edge's target names the node, not a second relation
    assert parse_edge("red_cube1(in)short_cabinet/drawer_low(open)") == (
        "red_cube1",
        "in",
        "short_cabinet/drawer_low",
    )


@pytest.mark.parametrize(
    ("message", "needle"),
    [
        ({"nodes": ["table", "box(open"], "edges": []}, "'box(open'"),
        ({"nodes": ["table", "box)("], "edges": []}, "'box)('"),
        ({"nodes": ["table", "cube"], "edges": ["cube(inside)table"]}, "unknown relation 'inside'"),
        ({"nodes": ["table", "cube"], "edges": ["cube(on)shelf"]}, "'cube(on)shelf'"),
        ({"nodes": ["table", "cube"], "edges": ["cube(on table"]}, "'cube(on table'"),
        ({"nodes": ["table", "cube"], "edges": ["cube on table"]}, "'cube on table'"),
        ({"nodes": ["table", "table"], "edges": []}, "duplicate node 'table'"),
        ({"nodes": ["cab/drawer_low(open)"], "edges": []}, "parent 'cab'"),
        ({"nodes": ["table", "cube"], "edges": ["cube(on)cube"]}, "'cube(on)cube'"),
        ({"nodes": "table", "edges": []}, "must be lists"),
    ],
)
def test_bad_messages_name_the_string(message: dict, needle: str) -> None:
    with pytest.raises(GSRError) as info:
        graph_from_gsr_bench(message)
    assert needle in str(info.value)


def test_writer_emits_state_suffixes_for_changed_graph(configs: list[dict]) -> None:
    g = graph_from_gsr_bench(configs[20]["scene_graph"])
    drawer = g.node("short_cabinet/drawer_low")
    opened = g.with_nodes([drawer.model_copy(update={"states": ("open",)})])
    assert "short_cabinet/drawer_low(open)" in gsr_bench_message(opened)["nodes"]
