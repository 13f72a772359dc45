"""Category registry and graph <-> state: facts, typing, graph_with_state round trips, apply_step."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from gsr.categories import AFFORDANCES, affordances, categories, category_of, get_category, synonyms
from gsr.errors import GSRError
from gsr.facts import facts, graph_with_state, problem_from_graph, state_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.pddl.model import Atom
from gsr.resources import data_dir, domain_path, load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.step import Step
from gsr.transition import StepRejected, apply_step, apply_steps


@pytest.fixture(scope="module")
def configs(published_gsr_bench_file: Path) -> list[dict]:
    """The published GSR-Bench dev configs (skipped when absent)."""
    return yaml.safe_load(published_gsr_bench_file.read_text(encoding="utf-8"))["configs"]


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


# ---------------------------------------------------------------- registry


@pytest.mark.parametrize(
    ("name", "category", "attrs"),
    [
        ("red_cube1", "cube", {"color": "red"}),
        ("blue_box", "box", {"color": "blue"}),
        ("akita_black_bowl", "bowl", {"color": "black"}),
        ("akita_black_bowl_2", "bowl", {"color": "black"}),
        ("white_yellow_mug", "mug", {"color": "white", "secondary_color": "yellow"}),
        ("porcelain_mug", "mug", {"color": "white", "material": "porcelain"}),
        ("short_cabinet", "cabinet", {"size": "short"}),
        ("drawer_low", "drawer", {"level": 0}),
        ("short_cabinet/drawer_middle", "drawer", {"level": 1}),
        ("alphabet_soup_1", "alphabet_soup", {}),
        ("wooden_cabinet_1", "cabinet", {"material": "wooden"}),
        ("orange_juice", "orange_juice", {}),  # 'orange' here is part of the name, not a colour
        ("yellow_book", "book", {"color": "yellow"}),
        ("flat_stove_1", "stove", {}),
        ("chefmate_8_frypan_1", "pan", {}),
        ("cookies_1", "cookie_box", {}),
        ("faucet", "tap", {}),
        ("grey_block3", "block", {"color": "grey"}),
        ("gray_cup", "cup", {"color": "grey"}),
        ("teapot.n.01_1", "pot", {}),
        ("zorblax_7", "thing", {}),
        ("", "thing", {}),
        ("___", "thing", {}),
    ],
)
def test_category_of(name: str, category: str, attrs: dict) -> None:
    assert category_of(name) == (category, attrs)


def test_affordances_follow_the_gsr_bench_rules() -> None:
    assert "supporter" not in affordances("cube") and "supporter" not in affordances("mug")
    assert "stackable" not in affordances("cube") and "stackable" in affordances("block")
    assert {"container", "openable"} <= affordances("drawer")
    assert {"container", "supporter", "openable"} <= affordances("lidded_box")
    assert "openable" not in affordances("box")
    assert "switchable" in affordances("stove") and "pressable" in affordances("button")
    assert affordances("zorblax") == frozenset({"movable"})  # unknown -> thing
    assert "counted" in affordances("cube") and "counted" not in affordances("mug")
    for cat in categories().values():
        assert cat.affordances <= set(AFFORDANCES), cat.name
    assert get_category("faucet").name == "tap"
    assert "faucet" in synonyms("tap")


# ---------------------------------------------------------------- resources


def test_resources_find_the_domain(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    assert domain_path().name == "tabletop.pddl"
    assert (data_dir() / "domains" / "tabletop.pddl").is_file()
    assert load_builtin_domain() is load_builtin_domain()  # cached
    with pytest.raises(GSRError, match="no built-in domain 'nope'"):
        domain_path("nope")
    monkeypatch.setenv("GSR_DATA", str(tmp_path / "missing"))
    with pytest.raises(GSRError, match="GSR_DATA"):
        data_dir()


# ---------------------------------------------------------------- facts


def test_facts_of_a_drawer_config(configs: list[dict], domain) -> None:
    g = graph_from_gsr_bench(next(c for c in configs if c["number"] == 107)["scene_graph"])
    f = facts(g)
    low, mid, high = (f"short_cabinet/drawer_{x}" for x in ("low", "middle", "high"))
    assert (
        Atom("above", (high, low)) in f and Atom("above", (mid, low)) in f and Atom("above", (high, mid)) in f
    )
    assert Atom("above", (low, high)) not in f
    assert Atom("part_of", (low, "short_cabinet")) in f
    assert Atom("open", (mid,)) in f and Atom("open", (low,)) not in f
    assert Atom("on", ("red_cube1", "table")) in f
    assert Atom("has_color", ("red_cube1", "red")) in f
    assert Atom("counted", ("red_cube1",)) in f and Atom("counted", ("red_mug1",)) not in f
    assert Atom("movable", (low,)) not in f  # parts are fixed
    assert Atom("cube_count", (low, "n0")) in f
    assert Atom("hand_empty", ()) in f
    assert Atom("next", ("n9", "n10")) in f
    state = state_from_graph(g, domain)
    assert state.objects["red_cube1"] == "cube" and state.objects[low] == "drawer"
    assert state.objects["n3"] == "count" and state.objects["red"] == "color"  # domain constants


def test_cube_count_is_derived_and_capped() -> None:
    nodes = [Node(id="table", category="table"), Node(id="box", category="box")]
    nodes += [Node(id=f"cube{i}", category="cube") for i in range(12)]
    nodes += [Node(id="mug", category="mug")]
    edges = [Edge(source=f"cube{i}", relation="in", target="box") for i in range(12)]
    edges += [
        Edge(source="mug", relation="in", target="box"),
        Edge(source="box", relation="on", target="table"),
    ]
    f = facts(SceneGraph(nodes=tuple(nodes), edges=tuple(edges)))
    assert {a for a in f if a.predicate == "cube_count"} == {Atom("cube_count", ("box", "n10"))}


def test_unknown_category_is_typed_thing(domain) -> None:
    g = SceneGraph(nodes=(Node(id="gizmo", category="gizmo"), Node(id="table", category="table")))
    assert state_from_graph(g, domain).objects["gizmo"] == "thing"
    assert Atom("movable", ("gizmo",)) in facts(g)


def test_graph_with_state_round_trips_every_config(gsr_bench_style_configs: list[dict], domain) -> None:
    for cfg in gsr_bench_style_configs:
        g = graph_from_gsr_bench(cfg["scene_graph"])
        back = graph_with_state(g, state_from_graph(g, domain))
        assert back.nodes == g.nodes, cfg["number"]
        assert set(back.edges) == set(g.edges), cfg["number"]


def test_problem_from_graph(configs: list[dict], domain) -> None:
    g = graph_from_gsr_bench(configs[0]["scene_graph"])
    goal = Atom("in", ("red_cube1", "blue_box"))
    p = problem_from_graph(g, goal, name="cfg1", domain=domain)
    assert p.domain_name == "tabletop" and p.name == "cfg1" and p.goal == goal
    assert p.objects["blue_box"] == "box" and "n0" not in p.objects
    assert p.init == facts(g)


def test_graph_with_state_rewrites_dynamic_part_only() -> None:
    g = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="cube", category="cube", attributes={"color": "red"}),
            Node(id="mug", category="mug"),
            Node(id="box", category="lidded_box", states=("closed",)),
            Node(id="lamp", category="lamp", states=("off",)),
        ),
        edges=(
            Edge(source="cube", relation="on", target="table"),
            Edge(source="cube", relation="left_of", target="mug"),
            Edge(source="mug", relation="on", target="table"),
            Edge(source="box", relation="on", target="table"),
        ),
    )
    atoms = {
        Atom("holding", ("cube",)),
        Atom("on", ("mug", "table")),
        Atom("on", ("box", "table")),
        Atom("open", ("box",)),
        Atom("turned_on", ("lamp",)),
        Atom("movable", ("cube",)),  # static atoms are ignored
    }
    h = graph_with_state(g, atoms)
    assert h.node("cube").states == ("held",) and h.node("cube").attributes == {"color": "red"}
    assert h.node("box").states == ("open",) and h.node("lamp").states == ("on",)
    # the held cube has no support, and its stale left_of relation is dropped
    assert {e.key() for e in h.edges} == {("mug", "on", "table"), ("box", "on", "table")}
    again = graph_with_state(h, {Atom("on", ("cube", "box")), *(a for a in atoms if a.predicate == "on")})
    assert again.node("box").states == ("closed",) and again.node("lamp").states == ("off",)
    assert ("cube", "on", "box") in {e.key() for e in again.edges}


# ---------------------------------------------------------------- transitions


def test_apply_steps_moves_a_cube_into_a_drawer(configs: list[dict], domain) -> None:
    g = graph_from_gsr_bench(next(c for c in configs if c["number"] == 107)["scene_graph"])
    steps = [
        Step("close", ("short_cabinet/drawer_high",)),
        Step("pick", ("red_cube1", "table")),
        Step("place_in", ("red_cube1", "short_cabinet/drawer_middle")),
    ]
    graphs = apply_steps(g, steps, domain)
    assert graphs[0].node("short_cabinet/drawer_high").states == ("closed",)
    assert graphs[1].node("red_cube1").states == ("held",)
    assert ("red_cube1", "in", "short_cabinet/drawer_middle") in {e.key() for e in graphs[2].edges}
    assert ("red_cube1", "on", "table") not in {e.key() for e in graphs[2].edges}
    assert graphs[2].node("red_cube1").states == ()
    assert Atom("cube_count", ("short_cabinet/drawer_middle", "n1")) in facts(graphs[2])


def test_apply_step_rejects_with_diagnosis(configs: list[dict], domain) -> None:
    g = graph_from_gsr_bench(next(c for c in configs if c["number"] == 107)["scene_graph"])
    with pytest.raises(StepRejected) as info:
        apply_step(g, Step("place_in", ("red_cube1", "short_cabinet/drawer_low")), domain)
    assert "place_in" in str(info.value)
    assert info.value.diagnosis.ok is False
    with pytest.raises(GSRError, match=r"step 2"):
        apply_steps(g, [Step("pick", ("red_cube1", "table")), Step("pick", ("red_cube2", "table"))], domain)
