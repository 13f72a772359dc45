"""LIBERO BDDL -> scene graph + tabletop problem: every file converts, goals are open, hand-checked cases."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.check import check_step
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.libero import libero_task
from gsr.pddl.bddl import load_bddl, parse_bddl
from gsr.pddl.model import And, Atom, Not
from gsr.resources import load_builtin_domain
from gsr.semantics import holds
from gsr.step import Step
from tests.data_paths import LIBERO as LIBERO_DIR

LIBERO = sorted(LIBERO_DIR.glob("*/*.bddl"))


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


def _task(suite: str, stem: str):
    return libero_task(load_bddl(LIBERO_DIR / suite / f"{stem}.bddl"))


def test_reference_files_present() -> None:
    assert len(LIBERO) == 40


@pytest.mark.parametrize("path", LIBERO, ids=[p.stem[:50] for p in LIBERO])
def test_every_file_converts_with_an_open_goal(path: Path, domain) -> None:
    graph, problem = libero_task(load_bddl(path))
    state = state_from_graph(graph, domain)
    assert problem.domain_name == "tabletop"
    assert set(problem.objects) == {n.id for n in graph.nodes}
    assert not holds(domain, problem.goal, state), "goal already satisfied initially"
    # every movable object stands somewhere; every node is typed by the domain
    supported = {e.source for e in graph.edges if e.relation in ("on", "in")}
    for node in graph.nodes:
        assert problem.objects[node.id] in domain.types
        if node.parent is None and node.category not in ("table", "floor"):
            assert node.id in supported, node.id


EXPECTED = [
    (
        "libero_10",
        "KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it",
        And(
            (
                Not(Atom("open", ("white_cabinet_1/bottom_drawer",))),
                Atom("in", ("akita_black_bowl_1", "white_cabinet_1/bottom_drawer")),
            )
        ),
    ),
    (
        "libero_10",
        "KITCHEN_SCENE3_turn_on_the_stove_and_put_the_moka_pot_on_it",
        And((Atom("turned_on", ("flat_stove_1",)), Atom("on", ("moka_pot_1", "flat_stove_1")))),
    ),
    (
        "libero_10",
        "STUDY_SCENE1_pick_up_the_book_and_place_it_in_the_back_compartment_of_the_caddy",
        And((Atom("in", ("black_book_1", "desk_caddy_1/back_compartment")),)),
    ),
    (
        "libero_10",
        "LIVING_ROOM_SCENE6_put_the_white_mug_on_the_plate_and_put_the_chocolate_pudding_to_the_right_of_the_plate",
        And(
            (
                Atom("on", ("porcelain_mug_1", "plate_1")),
                Atom("on", ("chocolate_pudding_1", "living_room_table/plate_right_region")),
            )
        ),
    ),
    (
        "libero_10",
        "KITCHEN_SCENE6_put_the_yellow_and_white_mug_in_the_microwave_and_close_it",
        And((Atom("in", ("white_yellow_mug_1", "microwave_1")), Not(Atom("open", ("microwave_1",))))),
    ),
    (
        "libero_goal",
        "push_the_plate_to_the_front_of_the_stove",
        And((Atom("on", ("plate_1", "main_table/stove_front_region")),)),
    ),
    ("libero_goal", "put_the_wine_bottle_on_the_rack", And((Atom("on", ("wine_bottle_1", "wine_rack_1")),))),
    (
        "libero_goal",
        "put_the_bowl_on_top_of_the_cabinet",
        And((Atom("on", ("akita_black_bowl_1", "wooden_cabinet_1/top_side")),)),
    ),
    (
        "libero_object",
        "pick_up_the_milk_and_place_it_in_the_basket",
        And((Atom("in", ("milk_1", "basket_1")),)),
    ),
]


@pytest.mark.parametrize(("suite", "stem", "goal"), EXPECTED, ids=[e[1][:40] for e in EXPECTED])
def test_hand_written_goals(suite: str, stem: str, goal) -> None:
    _, problem = _task(suite, stem)
    assert problem.goal == goal


def test_cabinet_drawers_levels_and_states() -> None:
    graph, _ = _task(
        "libero_10", "KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it"
    )
    drawers = {p.id: p for p in graph.parts("white_cabinet_1")}
    assert set(drawers) == {
        "white_cabinet_1/top_drawer",
        "white_cabinet_1/middle_drawer",
        "white_cabinet_1/bottom_drawer",
        "white_cabinet_1/top_side",
    }
    assert drawers["white_cabinet_1/bottom_drawer"].states == (
        "open",
    )  # (Open white_cabinet_1_bottom_region)
    assert drawers["white_cabinet_1/top_drawer"].states == ("closed",)
    assert [
        drawers[f"white_cabinet_1/{w}_drawer"].attributes["level"] for w in ("bottom", "middle", "top")
    ] == [0, 1, 2]
    assert drawers["white_cabinet_1/top_side"].category == "cabinet_top"
    edges = {e.key() for e in graph.edges}
    assert ("akita_black_bowl_1", "on", "kitchen_table") in edges  # init region collapses onto the table
    assert ("white_cabinet_1", "on", "kitchen_table") in edges
    assert ("wine_rack_1", "on", "kitchen_table") in edges


def test_spatial_init_relations() -> None:
    graph, _ = _task(
        "libero_spatial",
        "pick_up_the_black_bowl_in_the_top_drawer_of_the_wooden_cabinet_and_place_it_on_the_plate",
    )
    edges = {e.key() for e in graph.edges}
    assert ("akita_black_bowl_1", "in", "wooden_cabinet_1/top_drawer") in edges
    assert ("akita_black_bowl_2", "on", "wooden_cabinet_1/top_side") in edges
    assert graph.node("wooden_cabinet_1/top_drawer").states == ("open",)
    assert graph.node("flat_stove_1").states == ("off",)
    graph, _ = _task("libero_spatial", "pick_up_the_black_bowl_on_the_stove_and_place_it_on_the_plate")
    assert ("akita_black_bowl_1", "on", "flat_stove_1") in {e.key() for e in graph.edges}
    graph, _ = _task("libero_object", "pick_up_the_milk_and_place_it_in_the_basket")
    assert ("milk_1", "on", "floor") in {e.key() for e in graph.edges}


PLANS = [
    (
        "libero_10",
        "KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it",
        [("pick", "akita_black_bowl_1", "kitchen_table"), ("place_in", "akita_black_bowl_1", "white_cabinet_1/bottom_drawer"),
         ("close", "white_cabinet_1/bottom_drawer")],
    ),
    (
        "libero_10",
        "KITCHEN_SCENE3_turn_on_the_stove_and_put_the_moka_pot_on_it",
        [("turn_on", "flat_stove_1"), ("pick", "moka_pot_1", "kitchen_table"), ("place_on", "moka_pot_1", "flat_stove_1")],
    ),
    ("libero_goal", "push_the_plate_to_the_front_of_the_stove", [("push", "plate_1", "main_table", "main_table/stove_front_region")]),
    (
        "libero_goal",
        "open_the_top_drawer_and_put_the_bowl_inside",
        [("open", "wooden_cabinet_1/top_drawer"), ("pick", "akita_black_bowl_1", "main_table"),
         ("place_in", "akita_black_bowl_1", "wooden_cabinet_1/top_drawer")],
    ),
    (
        "libero_10",
        "STUDY_SCENE1_pick_up_the_book_and_place_it_in_the_back_compartment_of_the_caddy",
        [("pick", "black_book_1", "study_table"), ("place_in", "black_book_1", "desk_caddy_1/back_compartment")],
    ),
]  # fmt: skip


@pytest.mark.parametrize(("suite", "stem", "plan"), PLANS, ids=[p[1][:40] for p in PLANS])
def test_hand_written_plans_reach_the_goal(suite: str, stem: str, plan, domain) -> None:
    graph, problem = _task(suite, stem)
    state = state_from_graph(graph, domain)
    for action, *args in plan:
        assert not holds(domain, problem.goal, state)
        d = check_step(domain, state, Step(action, tuple(args)))
        assert d.ok, str(d)
        state = d.next_state
    assert holds(domain, problem.goal, state)


def test_fixtures_do_not_move(domain) -> None:
    graph, _ = _task(
        "libero_10", "STUDY_SCENE1_pick_up_the_book_and_place_it_in_the_back_compartment_of_the_caddy"
    )
    state = state_from_graph(graph, domain)
    assert not check_step(domain, state, Step("pick", ("desk_caddy_1", "study_table"))).ok


_BAD = """(define (problem p) (:domain robosuite)
  (:regions (a_region (:target main_table) (:ranges ((0 0 1 1)))))
  (:fixtures main_table - table) (:objects bowl_1 - akita_black_bowl)
  (:init (On bowl_1 main_table_a_region))
  (:goal (And (On bowl_1 nowhere_region))))
"""


def test_unknown_region_is_named() -> None:
    with pytest.raises(GSRError, match="nowhere_region"):
        libero_task(parse_bddl(_BAD, "bad.bddl"))


_SHELF = """(define (problem shelf_task) (:domain robosuite)
  (:language put the pan under the shelf, the soup in the tray and the mug on the microwave)
  (:regions
    (shelf_init_region (:target study_table) (:ranges ((0 0 0.1 0.1))))
    (top_side (:target wooden_two_layer_shelf_1))
    (top_region (:target wooden_two_layer_shelf_1))
    (bottom_region (:target wooden_two_layer_shelf_1))
    (contain_region (:target wooden_tray_1))
    (top_side (:target microwave_1))
    (heating_region (:target microwave_1)))
  (:fixtures study_table - study_table wooden_two_layer_shelf_1 - wooden_two_layer_shelf microwave_1 - microwave)
  (:objects chefmate_8_frypan_1 - chefmate_8_frypan wooden_tray_1 - wooden_tray soup_1 - alphabet_soup
            mug_1 - porcelain_mug)
  (:init (On wooden_two_layer_shelf_1 study_table_shelf_init_region) (On soup_1 wooden_two_layer_shelf_1_top_side))
  (:goal (And (In chefmate_8_frypan_1 wooden_two_layer_shelf_1_bottom_region) (In soup_1 wooden_tray_1_contain_region)
              (On mug_1 microwave_1_top_side) (Turnoff microwave_1))))
"""


def test_shelf_tray_and_microwave_regions(domain) -> None:
    graph, problem = libero_task(parse_bddl(_SHELF, "shelf.bddl"))
    # a shelf's levels are places to put things on, whatever the goal says (the graph never reads :goal);
    # the goal's "In" a level is read with the level's own predicate
    assert graph.node("wooden_two_layer_shelf_1/bottom_region").category == "region"
    assert graph.node("wooden_two_layer_shelf_1/top_region").category == "region"
    assert graph.node("microwave_1/top_side").category == "region"
    assert graph.node("microwave_1").states == ("closed", "off")
    assert problem.goal == And(
        (
            Atom("on", ("chefmate_8_frypan_1", "wooden_two_layer_shelf_1/bottom_region")),
            Atom("in", ("soup_1", "wooden_tray_1")),
            Atom("on", ("mug_1", "microwave_1/top_side")),
            Not(Atom("turned_on", ("microwave_1",))),
        )
    )
    edges = {e.key() for e in graph.edges}
    assert ("soup_1", "on", "wooden_two_layer_shelf_1/top_side") in edges
    assert ("chefmate_8_frypan_1", "on", "study_table") in edges  # no init support: on the table
    assert graph.metadata["language"].startswith("put the pan")
    state = state_from_graph(graph, domain)
    plan = [
        ("pick", "chefmate_8_frypan_1", "study_table"),
        ("place_on", "chefmate_8_frypan_1", "wooden_two_layer_shelf_1/bottom_region"),
        ("pick", "soup_1", "wooden_two_layer_shelf_1/top_side"),
        ("place_in", "soup_1", "wooden_tray_1"),
        ("pick", "mug_1", "study_table"),
        ("place_on", "mug_1", "microwave_1/top_side"),
    ]
    for action, *args in plan:
        d = check_step(domain, state, Step(action, tuple(args)))
        assert d.ok, str(d)
        state = d.next_state
    assert holds(domain, problem.goal, state)
