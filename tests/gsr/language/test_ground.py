"""Paraphrases and new combinations: synonyms, word order, plural/singular, verbs, optional articles, pronouns."""

from __future__ import annotations

import pytest

from gsr.language import ground
from gsr.pddl.writer import write_formula
from gsr.plan import plan_graph
from tests.gsr.language.conftest import ground_dnf
from tests.gsr.language.scene_fixture import scene

RED_IN_BLUE = "(and (forall (?x - cube) (imply (has_color ?x red) (in ?x blue_box))))"


def _goal(text: str) -> str:
    return " ".join(write_formula(ground(text, scene()).formula).split())


@pytest.mark.parametrize(
    "text",
    [
        "move all red_cubes into blue_box.",
        "Place all the red cubes in the blue box",
        "put every red cube into the blue box",
        "move each red cube to the blue box",
        "Please put all red cubes inside of the blue box.",
        "transfer all of the red cubes into blue_box",
        "put into the blue box all the red cubes",
        "into the blue box, put all red cubes",
    ],
)
def test_quantified_paraphrases(text: str) -> None:
    assert _goal(text) == RED_IN_BLUE


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("put red cubes into the blue box", "(and (in red_cube1 blue_box) (in red_cube2 blue_box))"),
        ("put the red cube that is in the blue box into the red box", "(and (in red_cube2 red_box))"),
        ("put the red cube on the table in the yellow box", "(and (in red_cube1 yellow_box))"),
        ("move the blue cube from the red box to the yellow box", "(and (in blue_cube1 yellow_box))"),
        ("put the cubes with the same color as the blue box into it", "(and (in blue_cube1 blue_box))"),
        ("pick up the milk and put it in the middle drawer", "(and (in milk short_cabinet/drawer_middle))"),
        (
            "grab the popcorn, then drop it into the lowest drawer and close it",
            "(and (in popcorn short_cabinet/drawer_low) (not (open short_cabinet/drawer_low)))",
        ),
        ("put milk in top drawer", "(and (in milk short_cabinet/drawer_high))"),
        ("put the milk in the open drawer", "(and (in milk short_cabinet/drawer_high))"),
        ("put the popcorn in the drawer that is open", "(and (in popcorn short_cabinet/drawer_high))"),
        (
            "open the closed drawers",
            "(and (open short_cabinet/drawer_low) (open short_cabinet/drawer_middle))",
        ),
        (
            "move the cube that has the same color as the yellow box into the yellow box",
            "(and (in yellow_cube1 yellow_box))",
        ),
        ("take the book out of the top drawer and put it on the table", "(and (on yellow_book table))"),
        ("open the bottom drawer", "(and (open short_cabinet/drawer_low))"),
        ("shut the upper drawer", "(and (not (open short_cabinet/drawer_high)))"),
        (
            "close drawer_high and open drawer_middle",
            "(and (not (open short_cabinet/drawer_high)) (open short_cabinet/drawer_middle))",
        ),
        (
            "pick up the red cubes and put them in the red box",
            "(and (in red_cube1 red_box) (in red_cube2 red_box))",
        ),
        ("put both mugs in the red box", "(and (in red_mug1 red_box) (in blue_mug1 red_box))"),
        (
            "put the red mug and the blue mug into the yellow box",
            "(and (in red_mug1 yellow_box) (in blue_mug1 yellow_box))",
        ),
        ("pick up the yellow book", "(and (holding yellow_book))"),
        (
            "put all items on the table into the yellow box",
            "(and (in red_cube1 yellow_box) (in yellow_cube1 yellow_box) (in red_mug1 yellow_box) "
            "(in blue_mug1 yellow_box) (in milk yellow_box) (in popcorn yellow_box))",
        ),
        (
            "put the mugs and cubes into the boxes of the same color",
            "(and (in red_mug1 red_box) (in blue_mug1 blue_box) (in red_cube1 red_box) (in red_cube2 red_box) "
            "(in blue_cube1 blue_box) (in yellow_cube1 yellow_box))",
        ),
    ],
)
def test_new_combinations(text: str, expected: str) -> None:
    assert _goal(text) == expected


def test_corresponding_paraphrases_agree() -> None:
    g = scene()

    def dnf(text: str) -> frozenset:
        return ground_dnf(ground(text, g).formula, g)

    a = dnf("Put all the mugs and cubes into their corresponding colored boxes")
    assert len(a) == 1 and len(next(iter(a))) == 6
    assert a == dnf("put every mug and cube in their matching coloured boxes")
    assert a == dnf("place the cubes and the mugs into the boxes of the same colour")


def test_different_drawers_is_an_injective_assignment() -> None:
    g = scene()
    goal = ground("put the yellow book, the milk and the popcorn in different drawers", g)
    dnf = ground_dnf(goal.formula, g)
    assert len(dnf) == 6  # 3! assignments of three items to three drawers
    for conj in dnf:
        drawers = {atom.args[1] for atom, _ in conj}
        assert len(drawers) == 3 and {atom.args[0] for atom, _ in conj} == {"yellow_book", "milk", "popcorn"}
    assert (
        ground_dnf(ground("place milk, popcorn and the book into different drawer layers", g).formula, g)
        == dnf
    )


def test_one_color_per_drawer() -> None:
    g = scene()
    goal = ground("sort all cubes and mugs into the drawers, one colour per drawer", g)
    dnf = ground_dnf(goal.formula, g)
    assert len(dnf) == 6  # 3 colours onto 3 drawers
    for conj in dnf:
        where = {atom.args[0]: atom.args[1] for atom, _ in conj}
        assert where["red_cube1"] == where["red_cube2"] == where["red_mug1"]
        assert len({where["red_cube1"], where["blue_cube1"], where["yellow_cube1"]}) == 3
    # under GSR-Bench's rules a cube resting on a box is stuck: plan on the scene with it on the table
    free = _with_blue_cube_on_table()
    plan = plan_graph(
        None,
        free,
        ground("sort all cubes and mugs into the drawers, one colour per drawer", free),
        timeout=120,
    )
    assert plan.solved


def _with_blue_cube_on_table():
    from gsr.gsr_bench_format import graph_from_gsr_bench
    from tests.gsr.language.scene_fixture import MESSAGE

    edges = [e if e != "blue_cube1(on)red_box" else "blue_cube1(on)table" for e in MESSAGE["edges"]]
    return graph_from_gsr_bench({"nodes": MESSAGE["nodes"], "edges": edges})


def test_goals_are_plannable() -> None:
    g = scene()
    for text in (
        "move every red cube to the blue box",
        "put the yellow cube in the yellow box and close the top drawer",
        "put the milk in the bottom drawer",
    ):
        assert plan_graph(None, g, ground(text, g), timeout=60).solved, text


def test_left_and_right_from_relation_edges() -> None:
    from gsr.scene_graph import Edge, Node, SceneGraph

    nodes = (
        Node(id="table", category="table"),
        Node(id="plate_a", category="plate"),
        Node(id="plate_b", category="plate"),
        Node(id="plate_c", category="plate"),
        Node(id="mug_1", category="mug", attributes={"color": "red"}),
    )
    edges = [Edge(source=n.id, relation="on", target="table") for n in nodes[1:]]
    edges += [
        Edge(source="plate_a", relation="left_of", target="plate_b"),
        Edge(source="plate_a", relation="left_of", target="plate_c"),
        Edge(source="plate_c", relation="right_of", target="plate_b"),
    ]
    g = SceneGraph(nodes=nodes, edges=tuple(edges))
    assert " ".join(write_formula(ground("put the red mug on the left plate", g).formula).split()) == (
        "(and (on mug_1 plate_a))"
    )
    assert " ".join(write_formula(ground("put the mug on the rightmost plate", g).formula).split()) == (
        "(and (on mug_1 plate_c))"
    )
    assert " ".join(write_formula(ground("put the mug on the right plate", g).formula).split()) == (
        "(and (on mug_1 plate_c))"
    )


def _lidded_scene():
    from gsr.gsr_bench_format import graph_from_gsr_bench

    g = graph_from_gsr_bench(
        {
            "nodes": ["table", "red_lid_box(closed)", "blue_box", "red_cube1", "red_cube2", "blue_cube1"],
            "edges": [
                "red_lid_box(on)table",
                "blue_box(on)table",
                "red_cube1(on)table",
                "red_cube2(on)table",
                "blue_cube1(on)table",
            ],
        }
    )
    lidded = g.node("red_lid_box").model_copy(update={"attributes": {"color": "red", "lid": True}})
    return g.with_nodes([lidded])


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "put all red cubes into the lidded box and close it",
            "(and (forall (?x - cube) (imply (has_color ?x red) (in ?x red_lid_box))) (not (open red_lid_box)))",
        ),
        ("put the blue cube in the box with a lid", "(and (in blue_cube1 red_lid_box))"),
        (
            "put the red cubes in the red box and close the lid",
            "(and (in red_cube1 red_lid_box) (in red_cube2 red_lid_box) (not (open red_lid_box)))",
        ),
        ("open the lid of the red box", "(and (open red_lid_box))"),
    ],
)
def test_lidded_boxes(text: str, expected: str) -> None:
    g = _lidded_scene()
    goal = ground(text, g)
    assert " ".join(write_formula(goal.formula).split()) == expected
    assert plan_graph(None, g, goal, timeout=60).solved


def test_stacking_blocks_and_one_anaphora() -> None:
    from gsr.scene_graph import Edge, Node, SceneGraph

    blocks = ("red_block", "blue_block", "green_block")
    g = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            *(Node(id=b, category="block", attributes={"color": b.split("_")[0]}) for b in blocks),
        ),
        edges=tuple(Edge(source=b, relation="on", target="table") for b in blocks),
    )
    cases = {
        "stack the red block on the blue block": "(and (on red_block blue_block))",
        "put the red block on the blue block and the green block on the red block": (
            "(and (on red_block blue_block) (on green_block red_block))"
        ),
        "put the red block on the green one": "(and (on red_block green_block))",
    }
    for text, expected in cases.items():
        goal = ground(text, g)
        assert " ".join(write_formula(goal.formula).split()) == expected
        assert plan_graph(None, g, goal, timeout=60).solved, text


def _rlbench_like_scene():
    from gsr.scene_graph import Edge, Node, SceneGraph

    nodes = (
        Node(id="table", category="table"),
        Node(id="basket", category="basket"),
        Node(id="tray", category="tray"),
        Node(id="popcorn", category="popcorn"),
        Node(id="butter", category="butter"),
        Node(id="rubbish_1", category="thing"),
        Node(id="rubbish_2", category="thing"),
        Node(id="panel", category="thing", attributes={"movable": False}),
        Node(id="panel/green_button", category="button", parent="panel", attributes={"color": "green"}),
        Node(id="panel/red_button", category="button", parent="panel", attributes={"color": "red"}),
        *(Node(id=f"{c}_cup", category="cup", attributes={"color": c}) for c in ("green", "red", "blue")),
    )
    edges = [
        Edge(source=n, relation="on", target="table")
        for n in ("basket", "tray", "rubbish_1", "rubbish_2", "panel")
    ]
    edges += [
        Edge(source="popcorn", relation="in", target="basket"),
        Edge(source="butter", relation="in", target="basket"),
    ]
    edges += [Edge(source=f"{c}_cup", relation="on", target="table") for c in ("green", "red", "blue")]
    return SceneGraph(nodes=nodes, edges=tuple(edges))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("empty the basket into the tray", "(and (in popcorn tray) (in butter tray))"),
        ("push the green button", "(and (turned_on panel/green_button))"),
        ("press the red button", "(and (turned_on panel/red_button))"),
        ("put the rubbish in the basket", "(and (in rubbish_1 basket) (in rubbish_2 basket))"),
        (
            "put the popcorn and the butter and the red cup in the tray",
            "(and (in popcorn tray) (in butter tray) (in red_cup tray))",
        ),
        ("place the popcorn, the butter in the tray", "(and (in popcorn tray) (in butter tray))"),
    ],
)
def test_unseen_verbs_and_lists(text: str, expected: str) -> None:
    assert " ".join(write_formula(ground(text, _rlbench_like_scene()).formula).split()) == expected


def test_stacking_a_tower_in_any_order() -> None:
    g = _rlbench_like_scene()
    goal = ground("stack the cups on the green cup", g)
    dnf = ground_dnf(goal.formula, g)
    assert len(dnf) == 2  # red on green and blue on red, or blue on green and red on blue
    for conj in dnf:
        below = {a.args[0]: a.args[1] for a, _ in conj}
        assert sorted(below) == ["blue_cup", "red_cup"] and "green_cup" in below.values()
    assert plan_graph(None, g, goal, timeout=60).solved
