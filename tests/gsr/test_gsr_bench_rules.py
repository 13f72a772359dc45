"""GSR-Bench's action rules (gsr.gsr_bench_rules): parsing, typed verdicts, replay; the status edge; the executor."""

from __future__ import annotations

import pytest

from gsr.errors import GSRError
from gsr.gsr_bench_format import graph_from_gsr_bench, gsr_bench_message
from gsr.gsr_bench_rules import Command, Rule, apply_command, check_command, parse_command, replay

SCENE = {
    "nodes": ["table", "red_box", "blue_box", "yellow_lid_box(closed)", "red_cube1", "blue_cube1", "red_mug1",
              "milk", "short_cabinet", "short_cabinet/drawer_low(closed)", "short_cabinet/drawer_middle(open)",
              "short_cabinet/drawer_high(closed)"],
    "edges": ["red_box(on)table", "blue_box(on)red_box", "yellow_lid_box(on)table", "red_cube1(on)table",
              "blue_cube1(in)red_box", "red_mug1(on)yellow_lid_box", "milk(in)short_cabinet/drawer_middle",
              "short_cabinet(on)table"],
}  # fmt: skip


@pytest.fixture()
def graph():
    return graph_from_gsr_bench(SCENE)


@pytest.mark.parametrize(
    ("text", "parsed"),
    [
        ("move red_cube1 in red_box", Command("move", "red_cube1", "in", "red_box")),
        ("Put red_cube1 into red_box.", Command("move", "red_cube1", "in", "red_box")),
        ("action type 2: move red_cube1 to table", Command("move", "red_cube1", "on", "table")),
        ("move red_cube1 upon red_box", Command("move", "red_cube1", "on", "red_box")),
        ("open short_cabinet/drawer_low", Command("open", "short_cabinet/drawer_low")),
        ("pick red_cube1", None),
        ("", None),
    ],
)
def test_parse_command(text, parsed) -> None:
    assert parse_command(text) == parsed


@pytest.mark.parametrize(
    ("command", "rule"),
    [
        ("move red_cube1 in red_box", Rule.TARGET_BLOCKED),  # blue_box lies on red_box
        ("move blue_cube1 on table", Rule.SOURCE_CONTAINER_BLOCKED),  # its box is covered
        ("move red_box on table", Rule.SOURCE_BLOCKED),
        ("move blue_box on yellow_lid_box", Rule.CONTAINER_IN_CONTAINER),
        ("move milk on red_cube1", Rule.NOT_A_SUPPORT),
        ("move milk on red_mug1", Rule.NOT_A_SUPPORT),
        ("move red_cube1 in short_cabinet/drawer_low", Rule.TARGET_CLOSED),
        ("move red_cube1 in yellow_lid_box", Rule.TARGET_BLOCKED),
        ("move red_cube1 on table", Rule.ALREADY_DONE),
        ("move ghost in red_box", Rule.UNKNOWN_OBJECT),
        ("open red_box", Rule.NOT_OPENABLE),
        ("open short_cabinet/drawer_middle", Rule.ALREADY_DONE),
        ("fly away", Rule.UNPARSABLE),
    ],
)
def test_each_rule_is_named(graph, command, rule) -> None:
    verdict = check_command(graph, command)
    assert not verdict.ok and verdict.rule is rule, verdict
    assert verdict.to_dict()["rule"] == rule.value and verdict.message


def test_drawer_order_and_the_open_close_laxity(graph) -> None:
    # GSR-Bench checks no drawer order when opening: the low drawer opens under the open middle one
    assert check_command(graph, "open short_cabinet/drawer_low").ok
    g = apply_command(graph, "open short_cabinet/drawer_low")
    verdict = check_command(g, "move red_cube1 in short_cabinet/drawer_low")
    assert verdict.rule is Rule.DRAWER_ORDER and "drawer_middle" in verdict.message
    g = apply_command(g, "close short_cabinet/drawer_middle")
    assert check_command(g, "move red_cube1 in short_cabinet/drawer_low").ok
    assert check_command(g, "move milk on table").rule is Rule.SOURCE_CONTAINER_CLOSED


def test_replay_applies_until_the_first_rejection(graph) -> None:
    done = replay(
        graph,
        ["move blue_box on table", "move red_cube1 in red_box", "move red_cube1 in red_box", "open red_box"],
    )
    assert [v.ok for v in done.verdicts] == [True, True, False]
    assert done.rejected.rule is Rule.ALREADY_DONE
    edges = gsr_bench_message(done.graph)["edges"]
    assert (
        "blue_box(on)table" in edges and "red_cube1(in)red_box" in edges and "red_cube1(on)table" not in edges
    )
    with pytest.raises(GSRError, match="target_blocked"):
        apply_command(graph, "move red_cube1 in red_box")


def test_a_moved_box_carries_its_contents(graph) -> None:
    g = apply_command(apply_command(graph, "move red_cube1 in blue_box"), "move blue_box on table")
    edges = gsr_bench_message(g)["edges"]
    assert (
        "red_cube1(in)blue_box" in edges
        and "blue_box(on)table" in edges
        and "blue_box(on)red_box" not in edges
    )


def test_table_status_edge_round_trips() -> None:
    full = graph_from_gsr_bench({"nodes": ["table", "red_cube1", "red_box"],
                                 "edges": ["red_cube1(in)red_box", "red_box(on)table", "0=F"]})  # fmt: skip
    assert "full" in full.node("table").states and full.metadata["rules"] == "gsr-bench"
    assert gsr_bench_message(full)["edges"][-1] == "0=F"
    assert check_command(full, "move red_cube1 on table").rule is Rule.TABLE_FULL
    free = graph_from_gsr_bench({"nodes": ["table", "red_cube1"], "edges": ["red_cube1(on)table", "0=T"]})
    assert "full" not in free.node("table").states and "0=F" not in gsr_bench_message(free)["edges"]
    with pytest.raises(GSRError, match="no 'table' node"):
        graph_from_gsr_bench({"nodes": ["red_cube1"], "edges": ["0=F"]})


def test_the_executor_judges_moves_under_the_rules(graph) -> None:
    from gsr.benchmarks.gsr_bench_executor import GSRBenchExecutor

    from gsr.diagnosis import ReasonKind
    from gsr.resources import load_builtin_domain
    from gsr.step import Step
    from gsr.task_spec import task_from_dict

    domain = load_builtin_domain("tabletop")
    task = task_from_dict(
        {
            "id": "t",
            "suite": "gsr-bench",
            "instructions": ["x"],
            "initial": graph,
            "goal": "(in red_cube1 blue_box)",
        }
    )
    ex = GSRBenchExecutor()
    ex.reset(task, domain)
    rejected = ex.execute(Step("turn_on", ("red_box",)))
    assert not rejected.ok and rejected.reasons[0].kind is ReasonKind.RULE_VIOLATION
    assert ex.execute(Step("pick", ("red_cube1", "table"))).ok
    assert ex.execute(Step("place_in", ("red_cube1", "blue_box"))).ok
    assert ex.commands == ["move red_cube1 in blue_box"]
    # the domain sees the covering box too, so only the benchmark's own checks are left to the rules
    assert not ex.execute(Step("pick", ("blue_cube1", "red_box"))).ok
