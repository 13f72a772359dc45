"""A container's cloud spilled over its neighbours, several cameras' wall pieces, one camera's piece of an
object: the fusion rules behind ``in`` without the oracle (exact synthetic clouds, no rendering)."""

from __future__ import annotations

import dataclasses

import numpy as np
from gsr.perception.evaluate import classify_in_errors
from gsr.perception.geometry import Instance, fit_boxes
from gsr.perception.relations import rim_box, supports
from gsr.perception.spill import carve_neighbours, spilled_points
from gsr.perception.track import absorb_fixture_pieces, absorb_fragments, absorb_object_pieces

from gsr.scene_graph import Edge, Node, SceneGraph
from tests.perception.test_containment import PARAMS, PLANE, TH, _inst, open_box, solid, table


def _named(inst: Instance, color: str | None = None, views: int | None = None) -> Instance:
    label = dataclasses.replace(inst.label, color=color)
    out = Instance(inst.key, label, inst.points, inst.rgb, views if views is not None else inst.views)
    fit_boxes(out)
    return out


def _rimless_box(views: int = 3) -> Instance:
    """A box a box stacked on it hides from above: its far (+x) wall and its floor (no rim to measure)."""
    wall = np.array(
        [(0.55, y, z) for y in np.arange(-0.1, 0.0701, 0.005) for z in np.arange(0.0, 0.0851, 0.005)]
    )
    xy = np.stack(np.meshgrid(np.arange(0.305, 0.5451, 0.005), np.arange(-0.095, 0.0651, 0.005)), -1)
    floor = np.column_stack([xy.reshape(-1, 2), np.full(xy.shape[0] * xy.shape[1], 0.008)])
    return _inst("box_1", "box", np.concatenate([wall, floor]), views)


def test_a_box_whose_cloud_spilled_over_a_mug_beside_it_no_longer_holds_the_mug():
    box = _rimless_box()
    mug = solid("mug_1", "mug", (0.25, -0.03, 0.0), (0.29, 0.01, 0.05), views=2)
    # one camera gave the box and the mug beside it one segment: the fused box reaches over the mug
    spilled = _inst("box_1", "box", np.concatenate([box.points, mug.points[mug.points[:, 2] > 0.049]]), 3)
    assert rim_box(spilled) is None and spilled.aabb_min[0] < 0.26
    assert supports([table(), spilled, mug], PLANE, TH)["mug_1"] == ("in", "box_1")
    out = carve_neighbours([table(), spilled, mug])
    carved = out[1]
    assert carved.aabb_min[0] >= 0.29 and len(carved.points) == len(box.points)
    assert supports([table(), carved, mug], PLANE, TH)["mug_1"] == ("on", "table")
    # one camera's mug (maybe a piece of the box itself) carves nothing
    assert carve_neighbours([table(), spilled, _named(mug, views=1)])[1] is spilled


def test_what_stands_in_or_rests_on_a_box_is_not_carved_out_of_it():
    box = open_box("box_1", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085), views=3)
    cube = solid("cube_1", "cube", (0.4, -0.03, 0.008), (0.43, 0.0, 0.038), views=3)
    carved = carve_neighbours([table(), box, cube])[1]
    # the floor under the cube goes, the walls (the box's extent) stay, and the cube is still in the box
    assert np.allclose(carved.aabb_min, box.aabb_min) and np.allclose(carved.aabb_max, box.aabb_max)
    assert supports([table(), carved, cube], PLANE, TH)["cube_1"] == ("in", "box_1")
    # a box stacked on it (its bottom at this box's top) takes nothing from it
    upper = open_box("box_2", (0.305, -0.095, 0.085), (0.545, 0.065, 0.17), views=3)
    assert not spilled_points(box, [box, upper]).any()
    # a small box inside a large one: the carve would take all of it, so none is made
    outer = open_box("box_3", (0.28, -0.12, 0.0), (0.6, 0.1, 0.12), views=3)
    assert not spilled_points(box, [box, outer]).any()


def test_a_wall_two_cameras_saw_of_the_containers_colour_joins_it_an_object_of_another_colour_does_not():
    box = _named(open_box("box_1", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085), views=4), "red")
    # the box's -x wall from the table to the rim, named a mug by two cameras (a stacked box hid the rest)
    wall = box.points[np.abs(box.points[:, 0] - 0.3) < 1e-6]
    strip = wall[(wall[:, 1] > 0.0) & (wall[:, 1] < 0.05)] - np.array([0.004, 0.0, 0.0])
    piece = _named(_inst("mug_1", "mug", strip), "red", views=2)
    out = absorb_fragments([box, piece], PARAMS)
    assert [i.key for i in out] == ["box_1"] and len(out[0].points) == len(box.points) + len(strip)
    # the same strip in blue is an object of its own; so is a red one that more cameras saw than the box
    assert len(absorb_fragments([box, _named(piece, "blue")], PARAMS)) == 2
    assert len(absorb_fragments([_named(box, "red", views=2), piece], PARAMS)) == 2


def test_one_cameras_piece_of_a_mug_joins_the_mug_but_a_cube_of_another_colour_beside_it_does_not():
    mug = _named(solid("mug_1", "mug", (0.4, -0.03, 0.008), (0.45, 0.02, 0.06), views=3), "yellow")
    rim = mug.points[mug.points[:, 2] > 0.055]
    piece = _named(_inst("box_2", "box", rim[rim[:, 1] < 0.0]), "yellow", views=1)
    out = absorb_object_pieces([table(), mug, piece], PARAMS)
    assert [i.key for i in out] == ["table", "mug_1"] and len(out[1].points) == len(mug.points) + len(
        piece.points
    )
    assert len(absorb_object_pieces([table(), mug, _named(piece, "red")], PARAMS)) == 3
    # a piece beside the mug, not inside its box, stays an object
    beside = _named(_inst("cube_3", "cube", rim + np.array([0.08, 0.0, 0.0])), "yellow", views=1)
    assert len(absorb_object_pieces([table(), mug, beside], PARAMS)) == 3
    # a cube standing where the mug stands, inside the mug's box (its segments took the cube's pixels)
    cube = _named(solid("cube_4", "cube", (0.41, -0.02, 0.008), (0.44, 0.01, 0.038)), "yellow", views=1)
    assert len(absorb_object_pieces([table(), mug, cube], PARAMS)) == 3


def test_in_relations_are_classified_one_by_one():
    nodes = [
        Node(id=n, category=c)
        for n, c in (("box", "box"), ("cube", "cube"), ("mug", "mug"), ("table", "table"))
    ]
    truth = SceneGraph(
        nodes=tuple(nodes),
        edges=(
            Edge(source="cube", relation="in", target="box"),
            Edge(source="mug", relation="on", target="table"),
        ),
    )
    pred = SceneGraph(
        nodes=tuple(nodes),
        edges=(
            Edge(source="cube", relation="on", target="table"),
            Edge(source="mug", relation="in", target="box"),
        ),
    )
    rows = classify_in_errors(pred, truth, {"box", "cube", "mug", "table"}, {"box", "cube", "mug", "table"})
    assert rows == [
        ("missed", "cube", "box", "on_instead_of_in"),
        ("false", "mug", "box", "in_instead_of_on"),
    ]


def test_one_cameras_sliver_of_a_cabinets_body_joins_it_but_what_stands_beside_or_in_it_does_not():
    cabinet = solid("cabinet_1", "cabinet", (0.3, -0.2, 0.0), (0.6, 0.15, 0.32), views=3)
    # a strip of the cabinet's side between two drawer levels, named milk by one camera
    side = cabinet.points[(np.abs(cabinet.points[:, 0] - 0.3) < 1e-6) & (cabinet.points[:, 2] > 0.14)]
    sliver = _inst("milk_1", "milk", side[side[:, 2] < 0.22])
    # the same strip from the table up (a milk carton against the side, its pixels in the cabinet's segment)
    low = _inst(
        "milk_2",
        "milk",
        cabinet.points[(np.abs(cabinet.points[:, 0] - 0.3) < 1e-6) & (cabinet.points[:, 2] < 0.07)],
    )
    # a cube in an open drawer in front of the carcass
    cube = solid("cube_1", "cube", (0.2, -0.05, 0.15), (0.23, -0.02, 0.18))
    out = absorb_fixture_pieces([table(), cabinet, sliver, low, cube], PARAMS)
    assert sorted(i.key for i in out) == ["cabinet_1", "cube_1", "milk_2", "table"]
    assert len(next(i for i in out if i.key == "cabinet_1").points) == len(cabinet.points) + len(
        sliver.points
    )
    # a cabinet one camera saw takes nothing
    assert len(absorb_fixture_pieces([table(), _named(cabinet, views=1), sliver], PARAMS)) == 3
