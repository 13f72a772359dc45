"""Scene-graph pictures: well-formed SVG that shows every node, edge label, state and highlight."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from gsr.graph_svg import scene_graph_svg
from gsr.gsr_bench_format import graph_from_gsr_bench

NS = "{http://www.w3.org/2000/svg}"


def _graph():
    return graph_from_gsr_bench(
        {
            "nodes": [
                "table",
                "short_cabinet",
                "short_cabinet/drawer_low(open)",
                "blue_box",
                "red_cube1",
                "red_cube2",
            ],
            "edges": [
                "short_cabinet(on)table",
                "blue_box(on)table",
                "red_cube1(in)short_cabinet/drawer_low",
                "red_cube2(on)blue_box",
            ],
        }
    )


def test_svg_is_well_formed_and_complete() -> None:
    graph = _graph()
    root = ET.fromstring(scene_graph_svg(graph, title="before <plan>", highlight=["red_cube1"]))
    texts = [t.text for t in root.iter(f"{NS}text")]
    for node in graph.nodes:
        assert any(node.id.split("/")[-1] in (t or "") for t in texts), node.id
    assert "before <plan>" in texts  # escaped in the file, restored by the XML parser
    assert texts.count("on") == 3 and texts.count("in") == 1
    assert any("[open]" in (t or "") for t in texts)
    outlined = [r for r in root.iter(f"{NS}rect") if r.get("stroke") == "#d0632a"]
    assert len(outlined) == 1


def test_supported_objects_are_drawn_above_their_support() -> None:
    root = ET.fromstring(scene_graph_svg(_graph()))
    y = {}
    for group_text in root.iter(f"{NS}text"):
        if group_text.get("font-weight") == "bold":
            y[group_text.text] = float(group_text.get("y"))
    assert y["red_cube2"] < y["blue_box"] < y["table"]
    assert y["red_cube1"] < y["short_cabinet"]  # in the cabinet's drawer: one row above the cabinet


def test_cyclic_support_does_not_hang() -> None:
    graph = graph_from_gsr_bench({"nodes": ["a_box", "b_box"], "edges": ["a_box(on)b_box", "b_box(on)a_box"]})
    assert scene_graph_svg(graph).startswith("<svg")
