"""A GSR-Bench-format scene used by the paraphrase, error and CLI tests (boxes, cubes, mugs, a cabinet)."""

from __future__ import annotations

from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.scene_graph import SceneGraph

MESSAGE = {
    "nodes": [
        "table",
        "red_box",
        "blue_box",
        "yellow_box",
        "red_cube1",
        "red_cube2",
        "blue_cube1",
        "yellow_cube1",
        "red_mug1",
        "blue_mug1",
        "short_cabinet",
        "short_cabinet/drawer_low(closed)",
        "short_cabinet/drawer_middle(closed)",
        "short_cabinet/drawer_high(open)",
        "milk",
        "popcorn",
        "yellow_book",
    ],
    "edges": [
        "red_box(on)table",
        "blue_box(on)table",
        "yellow_box(on)table",
        "red_cube1(on)table",
        "red_cube2(in)blue_box",
        "blue_cube1(on)red_box",
        "yellow_cube1(on)table",
        "red_mug1(on)table",
        "blue_mug1(on)table",
        "short_cabinet(on)table",
        "milk(on)table",
        "popcorn(on)table",
        "yellow_book(in)short_cabinet/drawer_high",
    ],
}


def scene() -> SceneGraph:
    """The fixture scene as a SceneGraph."""
    return graph_from_gsr_bench(MESSAGE)
