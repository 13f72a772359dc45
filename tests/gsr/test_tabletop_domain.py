"""The tabletop domain: structure, agreement with the category registry, and every GSR-Bench rule."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from gsr.categories import COLORS, categories
from gsr.check import check_step
from gsr.facts import COUNTS, facts, state_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.pddl.model import Atom
from gsr.pddl.parser import parse_domain
from gsr.pddl.writer import write_domain
from gsr.resources import domain_path, load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.semantics import apply
from gsr.state import State
from gsr.step import Step


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def configs(published_gsr_bench_file: Path) -> dict[int, dict]:
    """The published GSR-Bench dev configs by number (skipped when absent)."""
    raw = yaml.safe_load(published_gsr_bench_file.read_text(encoding="utf-8"))["configs"]
    return {c["number"]: c for c in raw}


def _graph(configs: dict[int, dict], number: int) -> SceneGraph:
    return graph_from_gsr_bench(configs[number]["scene_graph"])


def _run(domain, state: State, *steps: tuple[str, ...]) -> State:
    for action, *args in steps:
        d = check_step(domain, state, Step(action, tuple(args)))
        assert d.ok, str(d)
        state = d.next_state
    return state


def _rejected(domain, state: State, action: str, *args: str) -> str:
    d = check_step(domain, state, Step(action, tuple(args)))
    assert not d.ok, f"({action} {' '.join(args)}) should be rejected"
    return str(d)


# ---------------------------------------------------------------- structure


def test_domain_declares_the_registry(domain) -> None:
    assert domain.name == "tabletop"
    assert set(domain.actions) == {
        "pick", "place_on", "place_in", "open", "close", "turn_on", "turn_off", "press", "push", "stack",
    }  # fmt: skip
    for cat in categories().values():
        assert cat.name in domain.types, cat.name
        assert domain.types[cat.name] == (cat.parent,), cat.name
    assert {c for c, t in domain.constants.items() if t == "color"} == set(COLORS)
    assert {c for c, t in domain.constants.items() if t == "count"} == set(COUNTS)
    for p in (
        "movable",
        "container",
        "supporter",
        "openable",
        "switchable",
        "pressable",
        "pushable",
        "stackable",
    ):
        assert domain.predicates[p].arity == 1
    assert domain.predicates["cube_count"].arity == 2
    assert not domain.functions  # counting without numeric fluents


def test_domain_writes_and_reparses(domain) -> None:
    again = parse_domain(write_domain(domain), "written")
    assert (
        again.actions == domain.actions
        and again.types == domain.types
        and again.constants == domain.constants
    )
    assert domain_path().read_text(encoding="utf-8").count("(:action") == 10


def test_every_graph_fact_is_declared(configs, domain) -> None:
    for number in (1, 107, 122, 150):
        for atom in facts(_graph(configs, number)):
            assert atom.predicate in domain.predicates, atom
            assert len(atom.args) == domain.predicates[atom.predicate].arity, atom


# ---------------------------------------------------------------- GSR-Bench rules


def test_cannot_pick_a_box_with_something_on_it(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 122), domain)  # red_box on blue_box, yellow_box on red_box
    assert "(on yellow_box red_box)" in _rejected(domain, s, "pick", "red_box", "blue_box")
    s = _run(domain, s, ("pick", "yellow_box", "red_box"), ("place_on", "yellow_box", "table"))
    _run(domain, s, ("pick", "red_box", "blue_box"))


def test_cannot_open_a_lid_with_something_on_it(domain) -> None:
    g = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="box", category="lidded_box", states=("closed",)),
            Node(id="mug", category="mug"),
        ),
        edges=(
            Edge(source="box", relation="on", target="table"),
            Edge(source="mug", relation="on", target="box"),
        ),
    )
    s = state_from_graph(g, domain)
    _rejected(domain, s, "open", "box")
    _rejected(domain, _run(domain, s, ("pick", "mug", "box")), "open", "box")  # hand is full
    s = _run(domain, s, ("pick", "mug", "box"), ("place_on", "mug", "table"), ("open", "box"))
    _run(domain, s, ("pick", "mug", "table"), ("place_in", "mug", "box"), ("close", "box"))


def test_cannot_place_into_a_closed_drawer(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 107), domain)  # drawer_low closed, middle and high open
    s = _run(domain, s, ("pick", "red_cube1", "table"))
    _rejected(domain, s, "place_in", "red_cube1", "short_cabinet/drawer_low")
    _run(domain, s, ("place_in", "red_cube1", "short_cabinet/drawer_high"))


def test_drawer_reachable_only_while_drawers_above_are_closed(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 107), domain)
    _rejected(domain, s, "open", "short_cabinet/drawer_low")  # middle and high are open
    _rejected(domain, s, "close", "short_cabinet/drawer_middle")  # high is open
    s = _run(domain, s, ("close", "short_cabinet/drawer_high"))
    _rejected(domain, s, "open", "short_cabinet/drawer_low")  # middle still open
    s = _run(
        domain, s, ("pick", "red_cube1", "table"), ("place_in", "red_cube1", "short_cabinet/drawer_middle")
    )
    s = _run(domain, s, ("open", "short_cabinet/drawer_high"))
    _rejected(domain, s, "pick", "red_cube1", "short_cabinet/drawer_middle")  # take out: high is open again
    s = _run(domain, s, ("close", "short_cabinet/drawer_high"), ("close", "short_cabinet/drawer_middle"))
    s = _run(domain, s, ("open", "short_cabinet/drawer_low"))
    _rejected(domain, s, "pick", "red_cube1", "short_cabinet/drawer_middle")  # closed drawer
    s = _run(domain, s, ("pick", "red_cube2", "table"), ("place_in", "red_cube2", "short_cabinet/drawer_low"))
    assert Atom("in", ("red_cube2", "short_cabinet/drawer_low")) in s


def test_no_container_in_a_container(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 122), domain)
    s = _run(domain, s, ("pick", "yellow_box", "red_box"))
    _rejected(domain, s, "place_in", "yellow_box", "blue_box")
    _rejected(domain, s, "place_in", "yellow_box", "short_cabinet/drawer_high")
    _rejected(domain, s, "place_on", "yellow_box", "blue_box")  # nor onto one (GSR-Bench's validator)
    _run(domain, s, ("place_on", "yellow_box", "table"))


def test_nothing_on_a_cube_or_a_mug(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 122), domain)
    _rejected(domain, s, "pick", "milk", "blue_box")  # red_box lies on blue_box
    s = _run(domain, s, ("pick", "yellow_box", "red_box"), ("place_on", "yellow_box", "table"))
    s = _run(domain, s, ("pick", "red_box", "blue_box"), ("place_on", "red_box", "table"))
    s = _run(domain, s, ("pick", "milk", "blue_box"))
    _rejected(domain, s, "place_on", "milk", "red_cube1")
    _rejected(domain, s, "place_on", "milk", "red_mug1")
    _rejected(domain, s, "stack", "milk", "red_cube1")
    _run(domain, s, ("place_on", "milk", "table"))


def test_a_container_takes_at_most_ten_cubes(domain) -> None:
    nodes = [
        Node(id="table", category="table"),
        Node(id="box", category="box"),
        Node(id="mug", category="mug"),
    ]
    nodes += [Node(id=f"cube{i}", category="cube") for i in range(11)]
    edges = [Edge(source=n.id, relation="on", target="table") for n in nodes[1:]]
    s = state_from_graph(SceneGraph(nodes=tuple(nodes), edges=tuple(edges)), domain)
    for i in range(10):
        s = _run(domain, s, ("pick", f"cube{i}", "table"), ("place_in", f"cube{i}", "box"))
        assert Atom("cube_count", ("box", f"n{i + 1}")) in s
        assert Atom("cube_count", ("box", f"n{i}")) not in s
    s = _run(domain, s, ("pick", "cube10", "table"))
    _rejected(domain, s, "place_in", "cube10", "box")
    s = _run(domain, s, ("place_on", "cube10", "table"), ("pick", "mug", "table"), ("place_in", "mug", "box"))
    assert Atom("cube_count", ("box", "n10")) in s  # mugs do not count
    s = _run(domain, s, ("pick", "cube3", "box"))
    assert Atom("cube_count", ("box", "n9")) in s
    _run(
        domain, s, ("place_on", "cube3", "table"), ("pick", "cube10", "table"), ("place_in", "cube10", "box")
    )


def test_hand_holds_one_thing(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 107), domain)
    s = _run(domain, s, ("pick", "red_cube1", "table"))
    for action, args in [
        ("pick", ("red_cube2", "table")),
        ("open", ("short_cabinet/drawer_low",)),
        ("close", ("short_cabinet/drawer_high",)),
    ]:
        _rejected(domain, s, action, *args)
    _rejected(domain, s, "place_on", "red_cube1", "red_cube1")
    _rejected(domain, s, "pick", "table", "red_cube1")


# ---------------------------------------------------------------- other actions


def _devices() -> SceneGraph:
    return SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="table/front_region", category="region", parent="table"),
            Node(id="table/back_region", category="region", parent="table"),
            Node(id="lamp", category="lamp", states=("off",)),
            Node(id="lamp/button", category="button", parent="lamp"),
            Node(id="stove", category="stove"),
            Node(id="plate", category="plate"),
            Node(id="block_a", category="block"),
            Node(id="block_b", category="block"),
            Node(id="cabinet", category="cabinet"),
        ),
        edges=tuple(
            Edge(source=x, relation="on", target="table")
            for x in ("lamp", "stove", "plate", "block_a", "block_b", "cabinet")
        ),
    )


def test_press_toggles_button_and_owner(domain) -> None:
    s = state_from_graph(_devices(), domain)
    s = _run(domain, s, ("press", "lamp/button"))
    assert Atom("turned_on", ("lamp",)) in s and Atom("turned_on", ("lamp/button",)) in s
    s = _run(domain, s, ("press", "lamp/button"))
    assert Atom("turned_on", ("lamp",)) not in s
    _rejected(domain, s, "press", "lamp")


def test_turn_on_off(domain) -> None:
    s = state_from_graph(_devices(), domain)
    _rejected(domain, s, "turn_off", "stove")
    s = _run(domain, s, ("turn_on", "stove"))
    _rejected(domain, s, "turn_on", "stove")
    s = _run(domain, s, ("turn_off", "stove"))
    _rejected(domain, s, "turn_on", "plate")


def test_push_slides_along_one_surface(domain) -> None:
    s = state_from_graph(_devices(), domain)
    s = _run(domain, s, ("push", "plate", "table", "table/front_region"))
    s = _run(domain, s, ("push", "plate", "table/front_region", "table/back_region"))
    _rejected(domain, s, "push", "plate", "table/back_region", "stove")
    _rejected(domain, s, "push", "cabinet", "table", "table/front_region")  # fixtures do not slide


def test_stack_blocks(domain) -> None:
    s = state_from_graph(_devices(), domain)
    s = _run(domain, s, ("pick", "block_a", "table"))
    _rejected(domain, s, "place_on", "block_a", "block_b")  # blocks are stacked, not supporters
    s = _run(domain, s, ("stack", "block_a", "block_b"))
    _rejected(domain, s, "pick", "block_b", "table")  # block_a is on it
    s = _run(domain, s, ("pick", "block_a", "block_b"))
    assert Atom("holding", ("block_a",)) in s


def test_semantics_apply_agrees_with_checker(configs, domain) -> None:
    s = state_from_graph(_graph(configs, 1), domain)
    via_apply = apply(domain, s, "pick", ("red_cube1", "table"))
    via_check = _run(domain, s, ("pick", "red_cube1", "table"))
    assert via_apply.atoms == via_check.atoms
    assert Atom("hand_empty", ()) not in via_apply


def _gsr_graph(nodes: list[str], edges: list[str]) -> SceneGraph:
    from gsr.gsr_bench_format import graph_from_gsr_bench

    return graph_from_gsr_bench({"nodes": nodes, "edges": edges})


def test_a_covered_target_receives_nothing(domain) -> None:
    g = _gsr_graph(
        ["table", "red_box", "blue_box", "blue_mug1", "plate", "milk", "red_lid_box(closed)"],
        ["red_box(on)table", "blue_box(on)red_box", "blue_mug1(on)table", "plate(on)table", "milk(on)plate",
         "red_lid_box(on)table"],
    )  # fmt: skip
    s = _run(domain, state_from_graph(g, domain), ("pick", "blue_mug1", "table"))
    _rejected(domain, s, "place_in", "blue_mug1", "red_box")  # blue_box lies on it
    _rejected(domain, s, "place_on", "blue_mug1", "red_box")
    _rejected(domain, s, "place_on", "blue_mug1", "plate")  # GSR-Bench: any covered target
    _rejected(domain, s, "place_on", "blue_mug1", "red_lid_box")  # GSR-Bench: not even onto a closed lid
    s = _run(domain, s, ("place_in", "blue_mug1", "blue_box"))
    s = _run(
        domain, s, ("pick", "milk", "plate"), ("place_on", "milk", "table"), ("pick", "blue_mug1", "blue_box")
    )
    _run(domain, s, ("place_on", "blue_mug1", "plate"))


def test_a_cube_off_the_table_only_comes_out_of_an_uncovered_container(domain) -> None:
    g = _gsr_graph(
        ["table", "red_box", "blue_box", "red_cube1", "red_cube2", "red_mug1"],
        ["red_box(on)table", "blue_box(on)table", "red_cube1(on)red_box", "red_cube2(in)blue_box",
         "red_mug1(on)blue_box"],
    )  # fmt: skip
    s = state_from_graph(g, domain)
    _rejected(
        domain, s, "pick", "red_cube1", "red_box"
    )  # GSR-Bench counts the cube among its support's covers
    _rejected(domain, s, "pick", "red_cube2", "blue_box")  # red_mug1 covers blue_box
    s = _run(domain, s, ("pick", "red_mug1", "blue_box"), ("place_on", "red_mug1", "table"))
    _run(domain, s, ("pick", "red_cube2", "blue_box"), ("place_on", "red_cube2", "table"))


def test_a_full_table_receives_nothing(domain) -> None:
    g = _gsr_graph(["table", "red_box", "red_cube1"], ["red_box(on)table", "red_cube1(in)red_box", "0=F"])
    s = _run(domain, state_from_graph(g, domain), ("pick", "red_cube1", "red_box"))
    _rejected(domain, s, "place_on", "red_cube1", "table")
    _run(domain, s, ("place_in", "red_cube1", "red_box"))
