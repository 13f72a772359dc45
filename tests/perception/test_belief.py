"""Object permanence: objects hidden by a closed container persist; unexplained disappearances do not."""

from __future__ import annotations

from gsr.gsr_bench_format import graph_from_gsr_bench
from perception.belief import update_belief

CABINET = ["table", "cabinet_1", "cabinet_1/bottom_drawer({state})"]


def _g(nodes: list[str], edges: list[str], state: str = "open"):
    return graph_from_gsr_bench({"nodes": [n.format(state=state) for n in nodes], "edges": edges})


def test_object_in_a_closed_drawer_is_remembered() -> None:
    before = _g(
        [*CABINET, "black_bowl_1", "red_cube1"],
        ["cabinet_1(on)table", "black_bowl_1(in)cabinet_1/bottom_drawer", "red_cube1(on)table"],
    )
    after = _g(
        ["table", "cabinet_1", "cabinet_1/bottom_drawer(closed)", "red_cube1"],
        ["cabinet_1(on)table", "red_cube1(on)table"],
    )
    belief = update_belief(before, after)
    nodes = belief.node_map()
    assert nodes["black_bowl_1"].attributes["observed"] is False
    assert ("black_bowl_1", "in", "cabinet_1/bottom_drawer") in {e.key() for e in belief.edges}
    assert belief.metadata["remembered"] == ["black_bowl_1"]
    assert "closed" in nodes["cabinet_1/bottom_drawer"].states  # the observation wins for what is seen


def test_nested_support_inside_a_closed_container_is_remembered() -> None:
    before = _g(
        [*CABINET, "plate_1", "cube_1"],
        ["cabinet_1(on)table", "plate_1(in)cabinet_1/bottom_drawer", "cube_1(on)plate_1"],
    )
    after = _g(["table", "cabinet_1", "cabinet_1/bottom_drawer(closed)"], ["cabinet_1(on)table"])
    assert {"plate_1", "cube_1"} <= {n.id for n in update_belief(before, after).nodes}


def test_unexplained_disappearance_is_dropped() -> None:
    before = _g(
        [*CABINET, "black_bowl_1", "red_cube1"],
        ["cabinet_1(on)table", "black_bowl_1(in)cabinet_1/bottom_drawer", "red_cube1(on)table"],
    )
    # the drawer is seen open and empty, and the cube is gone from the table: nothing explains either
    after = _g(["table", "cabinet_1", "cabinet_1/bottom_drawer(open)"], ["cabinet_1(on)table"])
    belief = update_belief(before, after)
    assert {n.id for n in belief.nodes} == {"table", "cabinet_1", "cabinet_1/bottom_drawer"}
    assert update_belief(None, after) is after
