"""One camera's segment spanning two objects: split by colour, pieces fused or dropped; a container that is
its neighbours read as one; a box that took the box stacked on it (exact synthetic clouds, no rendering)."""

from __future__ import annotations

import numpy as np
import pytest
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import Instance, color_name, fit_boxes, point_color_names
from gsr.perception.relations import supports
from gsr.perception.spill import carve_neighbours, neighbours_read_as_container, spilled_points
from gsr.perception.track import drop_duplicate_views, fuse_views, join_under_stacked, split_stacked
from gsr.perception.view_split import SPLIT_PIECE, color_pieces, drop_unconfirmed_pieces, split_by_color

from tests.perception.test_containment import PARAMS, PLANE, TH, open_box, solid, table

RED, BLUE, YELLOW = (np.array(c, np.uint8) for c in ((200, 30, 30), (30, 40, 200), (220, 200, 40)))


def _coloured(
    key: str, category: str, parts: list[tuple[np.ndarray, np.ndarray]], views: int = 1
) -> Instance:
    pts = np.concatenate([p for p, _ in parts])
    rgb = np.concatenate([np.tile(c, (len(p), 1)) for p, c in parts])
    inst = Instance(key, InstanceLabel(category=category, color=color_name(rgb)), pts, rgb, views)
    fit_boxes(inst)
    return inst


def test_point_colour_names_follow_the_instance_rule_pixel_by_pixel():
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, size=(500, 3), dtype=np.uint8)
    assert point_color_names(rgb).tolist() == [color_name(p[None, :]) for p in rgb]


def test_one_segment_of_two_boxes_side_by_side_is_split_by_colour_and_each_piece_joins_its_box():
    red_box = open_box("r", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085)).points
    blue_box = open_box("b", (0.3, 0.08, 0.0), (0.55, 0.25, 0.085)).points
    # camera 0 gave both boxes one segment named blue; cameras 1 and 2 saw each box on its own
    both = _coloured("box_f0m1", "box", [(blue_box, BLUE), (red_box, RED)])
    pieces = split_by_color([both])
    assert len(pieces) == 2 and pieces[0].key == "box_f0m1" and pieces[0].label.color == "blue"
    assert pieces[1].label.category == "unknown" and pieces[1].label.color == "red"
    assert pieces[1].label.attributes[SPLIT_PIECE] and pieces[1].key.startswith("unknown_f0m")
    views = [both]
    for cam in (1, 2):
        views += [
            _coloured(f"box_f{cam}m1", "box", [(red_box, RED)]),
            _coloured(f"box_f{cam}m2", "box", [(blue_box, BLUE)]),
        ]
    fused = fuse_views(views, PARAMS)
    boxes = {i.label.color: i for i in fused}
    assert sorted(boxes) == ["blue", "red"] and all(i.views == 3 and i.label.category == "box" for i in fused)
    assert boxes["red"].aabb_min[1] == pytest.approx(-0.1) and boxes["red"].aabb_max[1] < 0.075
    assert boxes["blue"].aabb_min[1] > 0.075 and SPLIT_PIECE not in boxes["red"].label.attributes


def test_one_objects_colours_and_what_lies_inside_a_box_are_not_split():
    box = open_box("b", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085)).points
    cube = solid("c", "cube", (0.4, -0.03, 0.008), (0.46, 0.03, 0.068)).points
    assert color_pieces(_coloured("box_f0m1", "box", [(box, RED), (cube, BLUE)])) is None
    # a carton with a coloured band around its middle: the band lies in the carton's own box
    carton = solid("m", "milk", (0.3, 0.0, 0.0), (0.36, 0.06, 0.2)).points
    band = (carton[:, 2] > 0.08) & (carton[:, 2] < 0.12)
    one = _coloured("milk_f0m1", "milk", [(carton[~band], YELLOW), (carton[band], RED)])
    assert color_pieces(one) is None and split_by_color([one]) == [one]
    # a segment several cameras saw (fused) and a part are never split
    two_boxes = [(box, RED), (open_box("b", (0.3, 0.08, 0.0), (0.55, 0.25, 0.085)).points, BLUE)]
    assert split_by_color([_coloured("box_f0m1", "box", two_boxes, views=2)])[0].views == 2
    drawer = _coloured("drawer_f0m1", "drawer", two_boxes)
    assert split_by_color([drawer]) == [drawer]


def test_a_split_piece_no_other_camera_confirmed_is_dropped():
    red_box = open_box("r", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085)).points
    blue_box = open_box("b", (0.3, 0.08, 0.0), (0.55, 0.25, 0.085)).points
    both = _coloured("box_f0m1", "box", [(blue_box, BLUE), (red_box, RED)])
    main, piece = split_by_color([both])
    assert drop_unconfirmed_pieces([main, piece]) == [main]
    piece.views = 2  # two cameras' pieces fused: an object of its own
    kept = drop_unconfirmed_pieces([main, piece])
    assert len(kept) == 2 and SPLIT_PIECE not in kept[1].label.attributes


def test_a_carve_too_large_for_one_neighbour_does_not_stop_the_carve_of_another():
    box = open_box("box_1", (0.3, -0.1, 0.085), (0.55, 0.07, 0.17), floor=0.0, views=3)
    mug = solid("mug_1", "mug", (0.2, -0.03, 0.0), (0.25, 0.02, 0.05), views=2)
    # the box rests on a larger box whose fused cloud reaches up around it, and its cloud spilled over the mug
    spilled = Instance(
        "box_1", box.label, np.concatenate([box.points, mug.points]), np.zeros((0, 3), np.uint8), 3
    )
    spilled.rgb = np.full((len(spilled.points), 3), 128, np.uint8)
    fit_boxes(spilled)
    under = open_box("box_2", (0.28, -0.12, 0.0), (0.57, 0.09, 0.17), views=3)
    carved = spilled_points(spilled, [spilled, under, mug])
    assert carved.sum() == len(mug.points)


def test_a_container_one_camera_saw_over_confirmed_objects_is_those_objects_read_as_one():
    mug = solid("mug_1", "mug", (0.2, -0.03, 0.0), (0.25, 0.02, 0.05), views=2)
    book = solid("book_1", "book", (0.25, -0.03, 0.0), (0.28, 0.08, 0.065), views=2)
    seen_as_box = solid("box_1", "box", (0.2, -0.03, 0.0), (0.28, 0.08, 0.065), views=1)
    assert neighbours_read_as_container(seen_as_box, [seen_as_box, mug, book])
    assert [i.key for i in carve_neighbours([table(), seen_as_box, mug, book])] == [
        "table",
        "mug_1",
        "book_1",
    ]
    # two cameras saw it: a container; one camera's real box holding a mug keeps its walls outside the mug
    seen_as_box.views = 2
    assert not neighbours_read_as_container(seen_as_box, [seen_as_box, mug, book])
    box = open_box("box_2", (0.15, -0.1, 0.0), (0.35, 0.07, 0.085), views=1)
    inner = solid("mug_2", "mug", (0.2, -0.03, 0.008), (0.25, 0.02, 0.058), views=2)
    assert not neighbours_read_as_container(box, [box, inner])
    # several cameras' "box" that lies whole in two touching cubes' boxes is the cubes; a real box that
    # several cameras saw, with both cubes standing in it, is not
    left = solid("cube_1", "cube", (0.2, -0.03, 0.2), (0.25, 0.02, 0.25), views=3)
    right = solid("cube_2", "cube", (0.2, 0.02, 0.2), (0.25, 0.07, 0.25), views=3)
    pair = solid("box_4", "box", (0.2, -0.03, 0.2), (0.25, 0.07, 0.25), views=3)
    assert neighbours_read_as_container(pair, [pair, left, right])
    assert not neighbours_read_as_container(pair, [pair, left])
    holder = open_box("box_5", (0.15, -0.1, 0.19), (0.35, 0.12, 0.27), views=3)
    assert not neighbours_read_as_container(holder, [holder, left, right])
    # a box in a fixture's box (a cube in a drawer read as a box) is not its neighbours either
    cabinet = solid("cabinet_1", "cabinet", (0.1, -0.2, 0.0), (0.4, 0.2, 0.3), views=4)
    cube = solid("box_3", "box", (0.2, -0.03, 0.15), (0.24, 0.01, 0.19), views=1)
    assert not neighbours_read_as_container(cube, [cube, cabinet])


def test_a_box_that_took_the_box_stacked_on_it_is_cut_at_that_boxs_bottom_but_a_box_in_a_box_is_not():
    lower = open_box("lower", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085)).points
    upper = open_box("upper", (0.305, -0.095, 0.085), (0.545, 0.065, 0.17)).points
    # one view gave both boxes one segment that fused with the lower, red box's other views
    fused = _coloured("box_1", "box", [(lower, RED), (upper, YELLOW)], views=3)
    fused.label = InstanceLabel(category="box", color="red", attributes={})
    alone = upper[(upper[:, 1] < -0.094) | (np.abs(upper[:, 2] - 0.093) < 1e-6)]
    up = _coloured("box_2", "box", [(alone, YELLOW)], views=2)
    out = {i.label.color: i for i in split_stacked([fused, up], PARAMS)}
    assert out["red"].aabb_max[2] <= 0.085 and out["yellow"].aabb_min[2] >= 0.08
    assert len(out["yellow"].points) > len(alone)
    sup = supports([table(), out["red"], out["yellow"]], PLANE, TH)
    assert sup["box_1"] == ("on", "table") and sup["box_2"] == ("on", "box_1")
    # a yellow box standing on a red box's floor: not well above the red box's bottom, never cut
    outer = open_box("outer", (0.3, -0.1, 0.0), (0.55, 0.07, 0.17)).points
    inner = open_box("inner", (0.35, -0.06, 0.008), (0.5, 0.04, 0.08)).points
    whole = _coloured("box_1", "box", [(outer, RED), (inner, YELLOW)], views=3)
    whole.label = InstanceLabel(category="box", color="red")
    small = _coloured("box_2", "box", [(inner, YELLOW)], views=2)
    kept = split_stacked([whole, small], PARAMS)
    assert kept[0] is whole and kept[1] is small


def _from(inst: Instance, *cams: int) -> Instance:
    """``inst`` as fused from detections of the given cameras (its provenance)."""
    inst.label = InstanceLabel(
        category=inst.label.category,
        color=inst.label.color,
        attributes={"_members": tuple(f"f{c}m{k}" for k, c in enumerate(cams))},
    )
    inst.views = len(cams)
    return inst


def test_one_cameras_view_of_an_object_that_only_other_cameras_saw_is_dropped():
    cube = _from(solid("cube_1", "cube", (0.3, 0.0, 0.0), (0.34, 0.04, 0.04)), 0, 1, 3)
    # camera 2 saw the cube and a strip beside it and named it a mug: too large to fuse with the cube
    strip = solid("s", "mug", (0.3, 0.04, 0.0), (0.305, 0.05, 0.04)).points
    seen = _from(_coloured("mug_1", "mug", [(np.concatenate([cube.points, strip]), RED)]), 2)
    assert [i.key for i in drop_duplicate_views([cube, seen])] == ["cube_1"]
    # camera 1 saw the cube: then its second segment there is for the piece rules, not this one
    assert len(drop_duplicate_views([cube, _from(seen, 1)])) == 2
    # a cube standing against a box's wall on its floor lies partly on the box's cloud: kept
    box = _from(open_box("box_1", (0.2, -0.1, 0.0), (0.34, 0.1, 0.085)), 0, 1, 3)
    inner = _from(solid("cube_2", "cube", (0.295, 0.0, 0.008), (0.335, 0.04, 0.048)), 2)
    assert len(drop_duplicate_views([box, inner])) == 2


def test_two_halves_of_the_box_under_a_stacked_box_are_one_box_but_boxes_beside_it_are_not():
    lower = open_box("l", (0.3, -0.1, 0.0), (0.55, 0.07, 0.085)).points
    upper = _coloured(
        "box_1", "box", [(open_box("u", (0.305, -0.095, 0.085), (0.545, 0.065, 0.17)).points, RED)], views=4
    )
    # cameras saw the blue box's front and back wall bands below the red box apart: two fused blue boxes
    front = _coloured("box_2", "box", [(lower[lower[:, 1] < -0.04], BLUE)], views=3)
    # one camera named the back half a lidded box: the colour, not the name, says it is the same box
    back = _coloured("box_3", "lidded_box", [(lower[lower[:, 1] > 0.01], BLUE)], views=2)
    out = join_under_stacked([upper, front, back], PARAMS)
    assert [i.key for i in out] == ["box_1", "box_2"]
    assert out[1].aabb_min[1] == pytest.approx(-0.1) and out[1].aabb_max[1] == pytest.approx(0.07)
    sup = supports([table(), *out], PLANE, TH)
    assert sup["box_1"] == ("on", "box_2")
    # of another colour, or beside the upper box (not under it), they stay two
    other = _coloured("box_3", "box", [(lower[lower[:, 1] > 0.01], YELLOW)], views=2)
    assert len(join_under_stacked([upper, front, other], PARAMS)) == 3
    beside = _coloured("box_3", "box", [(lower[lower[:, 1] > 0.01] + [0.0, 0.2, 0.0], BLUE)], views=2)
    assert len(join_under_stacked([upper, front, beside], PARAMS)) == 3
