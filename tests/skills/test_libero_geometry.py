"""Object geometry and placement that LIBERO's scenes need: caddy compartments by name, level spots on
fixture tops (not on a stove's knob, not against a pot already there), objects turned to fit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from gsr.benchmarks.suites.libero_suite import task_from_bddl
from gsr.skills.assets import make_asset, make_book
from gsr.skills.build import build_world, resolve_part
from gsr.skills.packing import fitting_turn
from gsr.skills.surfaces import HANDLE_ROOM, hand_crowding, surface_spot

from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.task_spec import Layout, PlacedObject

BOOK = (0.03, 0.13, 0.1)


def _half(extent: tuple[float, float, float], yaw: float) -> np.ndarray:
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    return np.array([c * extent[0] + s * extent[1], s * extent[0] + c * extent[1]]) / 2


def test_caddy_compartments_resolve_by_their_side_and_each_holds_a_standing_book() -> None:
    caddy = make_asset("desk_caddy")
    graph = SceneGraph(
        nodes=(
            Node(id="desk_caddy_1", category="caddy"),
            *(
                Node(id=f"desk_caddy_1/{side}_compartment", category="compartment", parent="desk_caddy_1")
                for side in ("front", "back", "left", "right")
            ),
        ),
        edges=(),
    )
    seen = set()
    for side in ("front", "back", "left", "right"):
        part = resolve_part(caddy, graph, f"desk_caddy_1/{side}_compartment")
        assert part == f"compartment_{side}"
        seen.add(part)
        room = np.array(caddy.interiors[part].size[:2]) / 2
        turn = fitting_turn(BOOK, 0.0, 0.0, (float(room[0]), float(room[1])))
        assert np.all(_half(BOOK, turn) < room), side  # the book fits one way round
    assert len(seen) == 4
    # the four compartments do not overlap each other
    boxes = [caddy.interiors[p] for p in sorted(seen)]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            apart = [abs(a.center[k] - b.center[k]) >= (a.size[k] + b.size[k]) / 2 - 1e-9 for k in (0, 1)]
            assert any(apart)


def test_fitting_turn_keeps_the_smallest_turn_when_it_fits_and_turns_a_quarter_when_not() -> None:
    assert fitting_turn(BOOK, 0.0, 0.0, (0.05, 0.075)) == 0.0  # long side along the long room
    turned = fitting_turn(BOOK, 0.0, 0.0, (0.084, 0.0375))  # long room along x: a quarter turn
    assert abs(abs(turned) - math.pi / 2) < 1e-9
    assert fitting_turn(BOOK, 0.0, 0.1, (0.01, 0.01)) == 0.1  # fits nowhere: the smallest turn


def _stove_scene(pot_on_stove: bool) -> Layout:
    objects = [
        PlacedObject(id="flat_stove_1", asset="flat_stove", position=(0.1, 0.0, 0.0), fixed=True),
        PlacedObject(id="moka_pot_2", asset="moka_pot", position=(-0.15, 0.3, 0.0)),
    ]
    if pot_on_stove:
        objects.append(
            PlacedObject(id="moka_pot_1", asset="moka_pot", position=(0.1, 0.0, 0.0), on="flat_stove_1")
        )
    return Layout(objects=tuple(objects), table_size=(0.9, 1.2))


@pytest.mark.parametrize("pot_on_stove", [False, True])
def test_surface_spot_is_level_on_the_plate_clear_of_the_knob_and_of_a_pot_there(pot_on_stove: bool) -> None:
    graph = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="flat_stove_1", category="stove", attributes={"fixture": True}),
            Node(id="moka_pot_1", category="moka_pot"),
            Node(id="moka_pot_2", category="moka_pot"),
        ),
        edges=(Edge(source="moka_pot_1", relation="on", target="flat_stove_1"),),
    )
    with build_world(_stove_scene(pot_on_stove), seed=0, graph=graph) as w:
        stove, pot = w.objects["flat_stove_1"], w.objects["moka_pot_2"]
        lo, hi = w.body_aabb(stove.body)
        spot = surface_spot(w, pot, stove.body, lo, hi)
        assert spot is not None
        plate_top = w.layout.table_height + stove.model.extent[2]
        # the plate or the burner on it (6 mm), not the knob 4 cm higher
        assert plate_top - 0.001 <= spot[2] <= plate_top + 0.012
        assert hi[2] > plate_top + 0.02
        # the pot's footprint lies on the stove, away from the knob
        knob = w.to_world(stove.body, stove.links["knob"], (0, 0, 0))
        assert float(np.linalg.norm(spot[:2] - knob[:2])) > 0.03 + 0.022
        assert lo[0] + 0.03 <= spot[0] <= hi[0] - 0.03 and lo[1] + 0.03 <= spot[1] <= hi[1] - 0.03
        if pot_on_stove:
            other = w.objects["moka_pot_1"]
            olo, ohi = w.body_aabb(other.body)
            centre = (olo[:2] + ohi[:2]) / 2
            # not on the pot, and the hand setting it down does not meet the pot
            assert float(np.linalg.norm(spot[:2] - centre)) > 0.06
            assert not hand_crowding(w, pot, float(spot[2]))(spot)
        # the knob stays free for the hand that turns it
        assert float(np.linalg.norm(spot[:2] - knob[:2])) > HANDLE_ROOM


def test_book_asset_is_the_standing_book_the_caddy_is_sized_for() -> None:
    assert make_book(None, (0, 0, 0, 1)).extent == BOOK


@pytest.mark.physics
@pytest.mark.slow
@pytest.mark.parametrize(
    "suite,name",
    [
        ("libero_10", "KITCHEN_SCENE8_put_both_moka_pots_on_the_stove"),
        ("libero_10", "STUDY_SCENE1_pick_up_the_book_and_place_it_in_the_back_compartment_of_the_caddy"),
        ("libero_10", "KITCHEN_SCENE6_put_the_yellow_and_white_mug_in_the_microwave_and_close_it"),
        ("libero_10", "LIVING_ROOM_SCENE2_put_both_the_cream_cheese_box_and_the_butter_in_the_basket"),
        ("libero_goal", "put_the_cream_cheese_in_the_bowl"),
        ("libero_spatial", "pick_up_the_black_bowl_on_the_wooden_cabinet_and_place_it_on_the_plate"),
    ],
)
def test_libero_task_runs_physically(libero_dir: Path, suite: str, name: str) -> None:
    from gsr.benchmarks.agents import make_agent
    from gsr.benchmarks.runner import run_episode
    from gsr.skills.sim_executor import SimExecutor

    from gsr.resources import load_builtin_domain

    task = task_from_bddl(libero_dir / suite / f"{name}.bddl")
    ex = SimExecutor(seed=0, frame_camera=None)
    try:
        result = run_episode(task, make_agent("planner", {}), load_builtin_domain("tabletop"), executor=ex)
    finally:
        ex.close()
    assert result.success, result.reason


def _libero(libero_dir: Path, suite: str, name: str):
    return task_from_bddl(libero_dir / suite / f"{name}.bddl")


def test_an_object_in_a_drawer_that_starts_open_starts_in_it(libero_dir: Path) -> None:
    from gsr.skills.sim_graph import support_of

    task = _libero(
        libero_dir,
        "libero_spatial",
        "pick_up_the_black_bowl_in_the_top_drawer_of_the_wooden_cabinet_and_place_it_on_the_plate",
    )
    with build_world(task, seed=0) as w:
        assert support_of(w, "akita_black_bowl_1") == ("in", "wooden_cabinet_1/top_drawer")


def test_separation_keeps_objects_out_of_named_regions_they_do_not_start_in(libero_dir: Path) -> None:
    from gsr.skills.build import separate_footprints

    layout = _libero(libero_dir, "libero_goal", "put_the_cream_cheese_in_the_bowl").layout
    assert layout is not None
    shifts = separate_footprints(layout)
    region = next(r for r in layout.regions if r.name.endswith("stove_front_region"))
    x0, y0, x1, y1 = region.bounds
    for o in layout.objects:
        dx, dy = shifts.get(o.id, (0.0, 0.0))
        x, y = o.position[0] + dx, o.position[1] + dy
        started_in = x0 <= o.position[0] <= x1 and y0 <= o.position[1] <= y1
        assert started_in or not (x0 <= x <= x1 and y0 <= y <= y1), o.id


def test_microwave_top_and_shelf_levels_are_parts_of_their_own() -> None:
    microwave = make_asset("microwave")
    shelf = make_asset("wooden_two_layer_shelf")
    graph = SceneGraph(
        nodes=(
            Node(id="microwave_1", category="microwave"),
            Node(id="microwave_1/top_side", category="region", parent="microwave_1"),
            Node(id="shelf_1", category="shelf"),
            *(
                Node(id=f"shelf_1/{level}", category="region", parent="shelf_1")
                for level in ("bottom_region", "top_region", "top_side")
            ),
        ),
        edges=(),
    )
    assert resolve_part(microwave, graph, "microwave_1/top_side") == "top_side"
    assert [
        resolve_part(shelf, graph, f"shelf_1/{lv}") for lv in ("bottom_region", "top_region", "top_side")
    ] == [
        "bottom_region",
        "top_region",
        "top_side",
    ]


def test_shelf_levels_are_open_from_above_one_step_higher_each() -> None:
    layout = Layout(
        objects=(
            PlacedObject(id="shelf_1", asset="wooden_two_layer_shelf", position=(0.1, 0.0, 0.0), fixed=True),
            PlacedObject(id="book_1", asset="black_book", position=(-0.25, 0.35, 0.0)),
        ),
        table_size=(1.2, 1.6),
    )
    graph = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="shelf_1", category="shelf", attributes={"fixture": True}),
            *(
                Node(id=f"shelf_1/{lv}", category="region", parent="shelf_1")
                for lv in ("bottom_region", "top_region", "top_side")
            ),
            Node(id="book_1", category="book"),
        ),
        edges=(),
    )
    with build_world(layout, seed=0, graph=graph) as w:
        shelf, book = w.objects["shelf_1"], w.objects["book_1"]
        heights = []
        for lv in ("bottom_region", "top_region", "top_side"):
            link = shelf.links[lv]
            lo, hi = w.aabb(shelf.body, link)
            spot = surface_spot(w, book, shelf.body, lo, hi, links={link})
            assert spot is not None, lv  # a standing book fits on every level, seen from above
            heights.append(float(spot[2]))
        assert heights[0] < heights[1] < heights[2]


def test_a_microwave_is_entered_from_its_front_a_basket_from_above() -> None:
    from gsr.skills.articulated import roofed_opening

    layout = Layout(
        objects=(
            PlacedObject(id="microwave_1", asset="microwave", position=(0.2, 0.2, 0.0), fixed=True),
            PlacedObject(id="basket_1", asset="basket", position=(0.1, -0.3, 0.0)),
            PlacedObject(id="mug_1", asset="mug", position=(-0.2, 0.0, 0.0)),
        ),
        table_size=(1.2, 1.6),
    )
    graph = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="microwave_1", category="microwave", attributes={"fixture": True}),
            Node(id="basket_1", category="basket"),
            Node(id="mug_1", category="mug"),
        ),
        edges=(),
    )
    with build_world(layout, seed=0, graph=graph) as w:
        mug = w.objects["mug_1"]
        assert roofed_opening(w, "basket_1", mug) is None
        found = roofed_opening(w, "microwave_1", mug)
        assert found is not None
        spot, inward = found
        mw = w.objects["microwave_1"]
        lo, hi = w.aabb(mw.body, -1)
        assert inward == pytest.approx((1.0, 0.0), abs=1e-6)  # the door side faces the robot (-x)
        assert spot[0] < lo[0] + 0.01 and lo[1] < spot[1] < hi[1]  # before the opening, on the table
        assert spot[2] == pytest.approx(w.layout.table_height)
