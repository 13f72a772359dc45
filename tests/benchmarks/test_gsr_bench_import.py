"""The GSR-Bench importer on the 90 public dev configs: graph, layout units/frame, query-semantics goals."""

from __future__ import annotations

import copy
from collections import Counter

import pytest
import yaml
from gsr.benchmarks.scoring import any_goal
from gsr.benchmarks.suites.gsr_bench import load_configs, task_from_config, to_world

from gsr.errors import GSRError
from gsr.pddl.model import And, Atom
from gsr.plan.api import plan_graph


def _by_number(tasks: list, number: int):
    return next(t for t in tasks if t.metadata["number"] == number)


def test_all_90_configs_import(gsr_bench_tasks: list) -> None:
    assert len(gsr_bench_tasks) == 90
    assert len({t.id for t in gsr_bench_tasks}) == 90
    kinds = Counter(t.category for t in gsr_bench_tasks)
    assert kinds == {
        "move_all": 30,
        "color_per_drawer": 30,
        "corresponding_boxes": 15,
        "different_drawers": 15,
    }
    for t in gsr_bench_tasks:
        assert t.instruction and t.layout is not None
        assert t.metadata["unplaced"] == []  # every object of the graph got a pose from the lists


def test_move_all_goal_lists_exactly_the_matching_objects(gsr_bench_tasks: list) -> None:
    t = _by_number(gsr_bench_tasks, 1)  # "move all red_cubes into blue_box."
    f = t.goal_formula()
    assert isinstance(f, And)
    assert {p.args for p in f.parts} == {(f"red_cube{i}", "blue_box") for i in range(1, 7)}
    drawer = _by_number(gsr_bench_tasks, 111)  # "move all mugs into drawer_middle": LIBERO mugs included
    objs = set(drawer.metadata["goal_objects"])
    assert {"white_yellow_mug", "red_coffee_mug", "blue_mug1"} <= objs
    assert all(p.args[1] == "short_cabinet/drawer_middle" for p in drawer.goal_formula().parts)


def test_yellow_mugs_match_primary_colour_only(gsr_bench_tasks: list) -> None:
    t = _by_number(gsr_bench_tasks, 115)  # move all yellow_mugs into drawer_low
    assert "white_yellow_mug" not in t.metadata["goal_objects"]
    assert set(t.metadata["goal_objects"]) == {f"yellow_mug{i}" for i in range(1, 5)}


def test_corresponding_boxes_and_drawer_alternatives(gsr_bench_tasks: list) -> None:
    boxes = _by_number(gsr_bench_tasks, 121)
    for part in boxes.goal_formula().parts:
        obj, box = part.args
        assert obj.split("_")[0] == box.split("_")[0]  # same colour
    layers = _by_number(gsr_bench_tasks, 136)
    assert len(layers.goal_formulas()) == 6  # 3 items x 3 drawers, injective
    targets = {tuple(sorted(p.args[1] for p in f.parts)) for f in layers.goal_formulas()}
    assert targets == {tuple(sorted(f"short_cabinet/drawer_{d}" for d in ("low", "middle", "high")))}
    per_color = _by_number(gsr_bench_tasks, 151)
    assert len(per_color.goal_formulas()) == 6
    first = per_color.goal_formulas()[0]
    by_color: dict[str, set[str]] = {}
    for p in first.parts:
        by_color.setdefault(p.args[0].split("_")[0], set()).add(p.args[1])
    assert all(len(d) == 1 for d in by_color.values()) and len({d.pop() for d in by_color.values()}) == 3


def test_layout_is_metres_in_our_frame(gsr_bench_tasks: list, gsr_bench_file) -> None:
    t = _by_number(gsr_bench_tasks, 1)
    box = t.layout.object("blue_box")
    # benchmark (x, y, z) = (-11.70, 6.50, 7.14) cm; desk top 2 + box floor 4.5 below centre -> (-z, -x, y - 6.5) / 100
    assert box.position == pytest.approx((-0.07139, 0.11698, 0.0), abs=1e-4)
    assert to_world({"x": 100, "y": 0, "z": -50}, "p") == (0.5, -1.0, 0.0)
    cab = _by_number(gsr_bench_tasks, 107).layout.object("short_cabinet")
    assert cab.fixed and cab.joint_states == {"drawer_low": 0.0, "drawer_middle": 1.0, "drawer_high": 1.0}
    stacked = _by_number(gsr_bench_tasks, 9).layout.object("yellow_box")
    assert stacked.on == "blue_box" and stacked.position[2] > 0.05


@pytest.mark.parametrize("number", [1, 9, 107, 111, 121, 136])
def test_goals_plannable_fast_subset(gsr_bench_tasks: list, domain, number: int) -> None:
    t = _by_number(gsr_bench_tasks, number)
    result = plan_graph(domain, t.initial, any_goal(t), timeout=60)
    assert result.solved, result.message


@pytest.mark.slow
def test_all_90_goals_plannable(gsr_bench_tasks: list, domain) -> None:
    for t in gsr_bench_tasks:
        result = plan_graph(domain, t.initial, any_goal(t), timeout=120)
        assert result.solved, (t.id, result.message)


def _config(gsr_bench_file, number: int = 1) -> dict:
    return copy.deepcopy(next(c for c in load_configs(gsr_bench_file) if c["number"] == number))


def test_lidded_box_and_items_on_table_queries(gsr_bench_file, domain) -> None:
    cfg = _config(gsr_bench_file, 1)
    cfg["boxes_with_lid"] = [
        {
            "name": "red_lid_box",
            "position": {"x": 0, "y": 6.5, "z": 0},
            "rotation": 0,
            "colorIndex": 0,
            "isOpen": False,
        }
    ]
    cfg["scene_graph"]["nodes"].append("red_lid_box(closed)")
    cfg["scene_graph"]["edges"].append("red_lid_box(on)table")
    cfg["task_query"] = "put all items on the table into the red_lid_box and close it"
    t = task_from_config(cfg)
    goal_objects = set(t.metadata["goal_objects"])
    assert "blue_box" not in goal_objects and "red_lid_box" not in goal_objects  # containers stay out
    assert len(goal_objects) == 9
    assert Atom("open", ("red_lid_box",)) in {getattr(p, "formula", None) for p in t.goal_formula().parts}
    result = plan_graph(domain, t.initial, t.goal_formula(), timeout=60)
    assert result.solved
    actions = [s.action for s in result.plan.steps]
    assert actions[0] == "open" and actions[-1] == "close"
    assert t.layout.object("red_lid_box").asset == "box_with_lid"


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda c: c.pop("task_query"), "config 1: missing task_query"),
        (lambda c: c.update(task_query="dance with the robot"), "unsupported GSR-Bench task query"),
        (lambda c: c.update(task_query="move all green_cubes into blue_box"), "no object matches"),
        (lambda c: c.update(task_query="move all red_cubes into purple_box"), "'purple_box' is not a node"),
        (lambda c: c["scene_graph"]["edges"].append("red_cube1(on)ghost"), "dangling edge"),
        (lambda c: c["cubes"][0].update(colorIndex=9), "colorIndex must be 0..4"),
        (lambda c: c["boxes"][0].update(position={"x": "a"}), "position needs numeric x, y, z"),
    ],
)
def test_bad_configs_give_clear_errors(gsr_bench_file, mutate, message: str) -> None:
    cfg = _config(gsr_bench_file, 1)
    mutate(cfg)
    with pytest.raises(GSRError, match="config 1") as err:
        task_from_config(cfg, source="dev.yaml")
    assert message in str(err.value)


def test_bad_files(tmp_path) -> None:
    from gsr.benchmarks.suites.gsr_bench import load_gsr_bench

    bad = tmp_path / "bad.yaml"
    bad.write_text("configs: [\n")
    with pytest.raises(GSRError, match="invalid YAML"):
        load_gsr_bench(bad)
    bad.write_text(yaml.safe_dump({"configs": []}))
    with pytest.raises(GSRError, match="expected a 'configs' list"):
        load_gsr_bench(bad)
    with pytest.raises(GSRError, match="cannot read"):
        load_gsr_bench(tmp_path / "missing.yaml")
