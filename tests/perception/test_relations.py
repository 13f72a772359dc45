"""Relation rules on exact synthetic point clouds (no rendering): thresholds behave as documented."""

from __future__ import annotations

import math

import numpy as np
import pytest
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import Instance, fit_boxes
from gsr.perception.relations import (
    RelationThresholds,
    descriptive_relations,
    footprint_gap,
    in_ratio,
    supports,
)

TH = RelationThresholds()


def box_cloud(key, category, center, half, yaw=0.0, top=True, step=0.004) -> Instance:
    """Points on the visible surface of a box (top face and the four sides), exactly."""
    hx, hy, hz = half
    xs, ys, zs = (np.arange(-h, h + 1e-9, step) for h in half)
    faces = [np.array([(x, y, hz) for x in xs for y in ys])] if top else []
    faces += [np.array([(sx * hx, y, z) for y in ys for z in zs]) for sx in (-1, 1)]
    faces += [np.array([(x, sy * hy, z) for x in xs for z in zs]) for sy in (-1, 1)]
    pts = np.concatenate(faces)
    c, s = math.cos(yaw), math.sin(yaw)
    pts = pts @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]) + np.asarray(center)
    inst = Instance(key, InstanceLabel(id=key, category=category), pts, np.zeros((len(pts), 3), np.uint8))
    fit_boxes(inst)
    return inst


def table() -> Instance:
    return box_cloud("table", "table", (0.5, 0.0, -0.01), (0.5, 0.5, 0.01))


def test_upright_box_recovers_yaw_and_size():
    cube = box_cloud("c", "cube", (0.4, 0.1, 0.02), (0.03, 0.02, 0.02), yaw=0.5)
    assert cube.size[:2] == pytest.approx([0.06, 0.04], abs=0.003) or cube.size[:2] == pytest.approx(
        [0.04, 0.06], abs=0.003
    )
    assert cube.center == pytest.approx([0.4, 0.1, 0.02], abs=1e-3)


def test_stack_plate_and_table_supports():
    t = table()
    a = box_cloud("a", "cube", (0.4, 0.0, 0.02), (0.02, 0.02, 0.02))
    b = box_cloud("b", "block", (0.4, 0.0, 0.0575), (0.015, 0.015, 0.015))  # 2.5 mm above a's top
    plate = box_cloud("plate", "plate", (0.6, 0.2, 0.008), (0.09, 0.09, 0.008))
    c = box_cloud("c", "cube", (0.62, 0.2, 0.036), (0.02, 0.02, 0.02))
    sup = supports([t, a, b, plate, c], np.array([0, 0, 1.0, 0]), TH)
    assert sup == {"a": ("on", "table"), "b": ("on", "a"), "plate": ("on", "table"), "c": ("on", "plate")}


def test_gap_beyond_threshold_is_not_on_but_falls_back_to_the_surface_below():
    t = table()
    a = box_cloud("a", "cube", (0.4, 0.0, 0.02), (0.02, 0.02, 0.02))
    floating = box_cloud("f", "cube", (0.4, 0.0, 0.04 + TH.on_gap + 0.03), (0.02, 0.02, 0.02))
    sup = supports([t, a, floating], np.array([0, 0, 1.0, 0]), TH)
    assert sup["f"] == ("on", "a")  # nothing touches its bottom: the highest surface under it


def test_object_held_high_above_every_surface_rests_on_nothing():
    t = table()
    a = box_cloud("a", "cube", (0.4, 0.0, 0.02), (0.02, 0.02, 0.02))
    held = box_cloud("h", "bowl", (0.4, 0.0, 0.04 + TH.max_support_gap + 0.05), (0.05, 0.05, 0.025))
    sup = supports([t, a, held], np.array([0, 0, 1.0, 0]), TH)
    assert "h" not in sup and sup["a"] == ("on", "table")


def test_in_box_beats_on_and_needs_half_inside():
    t = table()
    box = box_cloud("box", "box", (0.5, 0.0, 0.04), (0.08, 0.08, 0.04), top=False)
    inside = box_cloud("x", "cube", (0.5, 0.0, 0.026), (0.02, 0.02, 0.02))
    half_out = box_cloud("y", "cube", (0.5, 0.095, 0.026), (0.02, 0.02, 0.02))  # 1/4 inside
    assert in_ratio(inside, box, TH) == 1.0
    assert in_ratio(half_out, box, TH) < TH.in_ratio
    sup = supports([t, box, inside], np.array([0, 0, 1.0, 0]), TH)
    assert sup["x"] == ("in", "box") and sup["box"] == ("on", "table")


def test_adjacent_and_directions_follow_the_robot_frame():
    t = table()
    a = box_cloud("a", "cube", (0.5, 0.0, 0.02), (0.02, 0.02, 0.02))
    left = box_cloud("l", "cube", (0.5, 0.06, 0.02), (0.02, 0.02, 0.02))  # 2 cm gap, +y = left
    far = box_cloud("f", "cube", (0.8, 0.0, 0.02), (0.02, 0.02, 0.02))  # 26 cm further from the robot
    insts = [t, a, left, far]
    sup = supports(insts, np.array([0, 0, 1.0, 0]), TH)
    rel = set(descriptive_relations(insts, sup, TH))
    assert footprint_gap(a, left) == pytest.approx(0.02, abs=0.002)
    assert {("a", "adjacent", "l"), ("l", "adjacent", "a")} <= rel
    assert ("a", "adjacent", "f") not in rel
    assert {("l", "left_of", "a"), ("a", "right_of", "l")} <= rel
    assert {("a", "front_of", "f"), ("f", "behind", "a")} <= rel
    # a robot turned 180 degrees about z swaps left/right and front/behind
    turned = np.diag([-1.0, -1.0, 1.0, 1.0])
    rel_turned = set(descriptive_relations(insts, sup, TH, turned))
    assert ("l", "right_of", "a") in rel_turned and ("a", "behind", "f") in rel_turned


def _top_heavy(inst: Instance, below_z: float) -> Instance:
    """Keep all points above ``below_z`` but only every 10th below: walls hide a tall object's lower part."""
    keep = (inst.points[:, 2] >= below_z) | (np.arange(len(inst.points)) % 10 == 0)
    out = Instance(inst.key, inst.label, inst.points[keep], inst.rgb[keep])
    fit_boxes(out)
    return out


def test_tall_object_mostly_seen_above_the_rim_is_in_the_basket():
    t = table()
    basket = box_cloud("basket", "basket", (0.5, 0.0, 0.05), (0.1, 0.08, 0.05), top=False)
    # a 14 cm bottle standing in a 10 cm basket, its lower part mostly hidden by the walls
    bottle = _top_heavy(box_cloud("bottle", "bottle", (0.5, 0.0, 0.075), (0.025, 0.025, 0.07)), 0.09)
    by_points = float(
        np.mean(
            basket.footprint_contains(bottle.points[:, :2], margin=0.005)
            & (bottle.points[:, 2] <= basket.aabb_max[2] + TH.in_rim)
        )
    )
    assert by_points < TH.in_ratio  # counting points alone would call it "on"
    assert in_ratio(bottle, basket, TH) >= TH.in_ratio  # most of its height span is inside
    sup = supports([t, basket, bottle], np.array([0, 0, 1.0, 0]), TH)
    assert sup["bottle"] == ("in", "basket")
    beside = box_cloud("b2", "bottle", (0.5, 0.2, 0.065), (0.025, 0.025, 0.065))
    assert in_ratio(beside, basket, TH) == 0.0  # outside the footprint: not in, however tall


def test_furniture_seen_only_from_above_rests_on_the_table():
    t = table()
    # only the top face of a 32 cm cabinet is visible (a top camera): its visible bottom is 32 cm up
    top = box_cloud("cab", "cabinet", (0.5, 0.0, 0.16), (0.15, 0.15, 0.16))
    top_only = top.points[top.points[:, 2] > 0.319]
    cab = Instance("cab", top.label, top_only, np.zeros((len(top_only), 3), np.uint8))
    fit_boxes(cab)
    sup = supports([t, cab], np.array([0, 0, 1.0, 0]), TH)
    assert sup["cab"] == ("on", "table")  # furniture cannot float
    # the same surface as a movable object (held high by the robot) rests on nothing
    bowl = Instance("bowl", InstanceLabel(id="bowl", category="bowl"), top_only, cab.rgb)
    fit_boxes(bowl)
    assert "bowl" not in supports([t, bowl], np.array([0, 0, 1.0, 0]), TH)


def test_innermost_container_wins():
    """A cube in a box that stands in a wider box is in the inner box (its floor is the higher one)."""
    t = table()
    outer = box_cloud("outer", "box", (0.5, 0.0, 0.05), (0.12, 0.12, 0.05), top=False)
    inner = box_cloud("inner", "box", (0.5, 0.0, 0.045), (0.07, 0.07, 0.035), top=False)
    cube = box_cloud("x", "cube", (0.5, 0.0, 0.04), (0.02, 0.02, 0.02))
    assert in_ratio(cube, outer, TH) == 1.0 and in_ratio(cube, inner, TH) == 1.0  # a tie on the ratio
    sup = supports([t, outer, inner, cube], np.array([0, 0, 1.0, 0]), TH)
    assert sup["x"] == ("in", "inner") and sup["inner"] == ("in", "outer")


def test_closed_container_holds_only_what_lies_under_its_lid():
    t = table()
    box = box_cloud("box", "box", (0.5, 0.0, 0.06), (0.08, 0.08, 0.06))
    # a book standing inside, its top showing 1.5 cm under the (lifted) lid
    book = box_cloud("book", "book", (0.5, 0.0, 0.0525), (0.015, 0.06, 0.0525))
    on_lid = box_cloud("c", "cube", (0.45, 0.0, 0.14), (0.02, 0.02, 0.02))  # resting on the closed lid
    sup = supports([t, box, book, on_lid], np.array([0, 0, 1.0, 0]), TH, closed=frozenset({"box"}))
    assert sup["book"] == ("in", "box")
    assert sup["c"] == ("on", "box")


def test_object_off_the_table_rests_on_no_plane():
    """The fitted plane is unbounded; an object beside the table (fallen, thrown) is not on it."""
    t = table()
    off = box_cloud("o", "cube", (1.3, 0.0, 0.02), (0.02, 0.02, 0.02))  # the table spans x 0..1
    edge = box_cloud("e", "cube", (0.99, 0.0, 0.02), (0.02, 0.02, 0.02))  # overhanging the edge
    sup = supports([t, off, edge], np.array([0, 0, 1.0, 0]), TH)
    assert "o" not in sup and sup["e"] == ("on", "table")


def test_object_on_a_flat_lid_the_cavity_test_missed_rests_on_the_box():
    """A lidded box perceived open (closed lid, but the cavity test said open): its flat top around the
    cube is at the cube's bottom, so the cube is on the box; in an open box the floor lies far below."""
    t = table()
    lidded = box_cloud("lb", "lidded_box", (0.5, 0.0, 0.05), (0.08, 0.08, 0.05))  # flat top at 0.10
    tab = box_cloud("tab", "lidded_box", (0.5, -0.06, 0.115), (0.01, 0.01, 0.015))  # the lid's grip tab
    lidded.points = np.concatenate([lidded.points, tab.points])
    fit_boxes(lidded)
    cube = box_cloud("c", "cube", (0.5, 0.0, 0.12), (0.02, 0.02, 0.02))
    assert in_ratio(cube, lidded, TH) >= TH.in_ratio  # the tab lifts the box's top: "in" by the ratio
    sup = supports([t, lidded, cube], np.array([0, 0, 1.0, 0]), TH)
    assert sup["c"] == ("on", "lb")
    open_box = box_cloud("ob", "lidded_box", (0.5, 0.0, 0.05), (0.08, 0.08, 0.05), top=False)
    floor = box_cloud("ob_floor", "lidded_box", (0.5, 0.0, 0.004), (0.08, 0.08, 0.004))
    open_box.points = np.concatenate([open_box.points, floor.points])
    fit_boxes(open_box)
    inside = box_cloud("x", "cube", (0.5, 0.0, 0.028), (0.02, 0.02, 0.02))
    sup = supports([t, open_box, inside], np.array([0, 0, 1.0, 0]), TH)
    assert sup["x"] == ("in", "ob")
