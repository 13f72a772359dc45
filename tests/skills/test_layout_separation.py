"""Layout separation at build time: rectangles for large footprints, the desk's edges, drawer sweeps."""

from __future__ import annotations

import math

import numpy as np
from gsr.skills.assets import make_asset
from gsr.skills.build import HAND_CLEARANCE, drawer_sweep, rect_overlap, separate_footprints

from gsr.task_spec import Layout, PlacedObject

BOX = (0.17, 0.25, 0.085)
TABLE = (0.6, 1.2)


def _moved(layout: Layout) -> dict[str, np.ndarray]:
    shifts = separate_footprints(layout)
    return {o.id: np.array(o.position[:2]) + np.array(shifts.get(o.id, (0.0, 0.0))) for o in layout.objects}


def test_rect_overlap_is_none_when_apart_and_the_shortest_push_otherwise() -> None:
    a = (np.array([0.1, 0.05]), 0.0)
    b = (np.array([0.1, 0.05]), 0.0)
    assert rect_overlap(np.array([0.3, 0.0]), a, b, 0.01) is None
    u, amount = rect_overlap(np.array([0.15, 0.02]), a, b, 0.01)
    # along y the rectangles overlap by 0.05 + 0.05 + 0.01 - 0.02 = 0.09 < along x (0.06 + ...)
    assert abs(u @ np.array([1.0, 0.0])) > 0.99 or abs(u @ np.array([0.0, 1.0])) > 0.99
    assert amount > 0
    # the push separates them
    d = np.array([0.15, 0.02]) + u * amount
    assert rect_overlap(d, a, b, 0.01) is None


def test_a_box_next_to_a_cabinet_stays_on_the_desk() -> None:
    # the circumscribed circles of a 17 x 25 cm box and a 28 x 36 cm cabinet 16 cm apart pushed the box
    # 25 cm away, off a 60 cm deep desk
    cab = PlacedObject(id="cab", asset="short_cabinet", position=(-0.055, 0.257, 0.0), fixed=True)
    box = PlacedObject(id="box", asset="box_with_lid", position=(0.103, 0.258, 0.0), size=BOX, yaw=0.31)
    pos = _moved(Layout(objects=(cab, box), table_size=TABLE))
    extent = make_asset("box_with_lid", BOX).extent
    assert abs(pos["box"][0]) + max(extent[:2]) / 2 <= TABLE[0] / 2 + 1e-6
    assert abs(pos["box"][1]) + max(extent[:2]) / 2 <= TABLE[1] / 2 + 1e-6
    assert np.allclose(pos["cab"], cab.position[:2])  # fixtures stay


def test_nothing_stays_in_front_of_a_cabinets_drawers() -> None:
    cab = PlacedObject(id="cab", asset="short_cabinet", position=(0.15, 0.06, 0.0), fixed=True)
    mug = PlacedObject(id="mug", asset="mug", position=(-0.12, 0.05, 0.0), size=(0.044, 0.044, 0.05))
    pos = _moved(Layout(objects=(cab, mug), table_size=TABLE))
    model = make_asset("short_cabinet", None)
    sweep = drawer_sweep(model)
    assert sweep > 0.2  # the drawers open over 20 cm
    front = cab.position[0] - model.extent[0] / 2
    # the mug is either beyond the sweep in x or beside the cabinet in y, with a hand's width of room
    half_mug = max(make_asset("mug", (0.044, 0.044, 0.05)).extent[:2]) / 2
    beside = abs(pos["mug"][1] - cab.position[1]) >= model.extent[1] / 2 + HAND_CLEARANCE
    beyond = pos["mug"][0] + half_mug <= front - sweep
    assert beside or beyond
    assert abs(pos["mug"][0]) <= TABLE[0] / 2  # and still on the desk


def test_small_objects_keep_the_circle_rule_and_separation_is_deterministic() -> None:
    cubes = tuple(
        PlacedObject(id=f"c{i}", asset="cube", position=(0.01 * i, 0.0, 0.0), size=(0.03, 0.03, 0.03))
        for i in range(3)
    )
    layout = Layout(objects=cubes, table_size=TABLE)
    assert separate_footprints(layout) == separate_footprints(layout)
    pos = _moved(layout)
    r = math.hypot(0.03, 0.03) / 2
    for i in range(3):
        for j in range(i + 1, 3):
            assert np.linalg.norm(pos[f"c{i}"] - pos[f"c{j}"]) >= 2 * r
