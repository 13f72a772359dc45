"""Which side a lidded box's sliding lid opens to: the clearest one, never far past the near edge."""

from __future__ import annotations

import math

import pytest
from gsr.skills.build import lid_side_yaw

from gsr.task_spec import Layout, PlacedObject

BOX = (0.17, 0.25, 0.085)


def _choose(box: PlacedObject, *others: PlacedObject, table: tuple[float, float] = (0.6, 1.2)) -> float:
    layout = Layout(objects=(box, *others), table_size=table)
    return lid_side_yaw(layout, box)


def _angle(a: float, b: float) -> float:
    return abs(math.remainder(a - b, 2 * math.pi))


def test_lid_opens_away_from_a_cube_on_its_side() -> None:
    box = PlacedObject(id="box", asset="box_with_lid", position=(0.0, 0.0, 0.0), size=BOX, yaw=0.0)
    # the lid slides along the box's +y: a cube 30 cm along +y would sit under the open lid
    cube = PlacedObject(id="cube", asset="cube", position=(0.0, 0.3, 0.0), size=(0.03, 0.03, 0.03))
    assert _angle(_choose(box, cube), math.pi) < 1e-6
    # with the cube on the other side the layout's yaw stands
    other = cube.model_copy(update={"position": (0.0, -0.3, 0.0)})
    assert _angle(_choose(box, other), 0.0) < 1e-6


def test_lid_does_not_hang_far_past_the_near_edge() -> None:
    # yaw pi/2 slides the lid towards -x, the robot's side: 0.25 m beyond a box 5 cm from the edge
    # (the robot's base pushed such lids shut); even a cube on the far side does not make that side worse
    box = PlacedObject(id="box", asset="box_with_lid", position=(-0.2, 0.0, 0.0), size=BOX, yaw=math.pi / 2)
    cube = PlacedObject(id="cube", asset="cube", position=(0.1, 0.0, 0.0), size=(0.03, 0.03, 0.03))
    assert _angle(_choose(box, cube), -math.pi / 2) < 1e-6
    # away from the edge the robot's side is fine, and the cube-free side wins
    inner = box.model_copy(update={"position": (0.1, 0.0, 0.0)})
    far = cube.model_copy(update={"position": (0.4, 0.0, 0.0)})
    assert _angle(_choose(inner, far, table=(1.2, 1.2)), math.pi / 2) < 1e-6


def test_boxes_without_a_lid_keep_their_yaw() -> None:
    box = PlacedObject(id="box", asset="box", position=(0.0, 0.0, 0.0), size=BOX, yaw=0.7)
    cube = PlacedObject(id="cube", asset="cube", position=(0.0, 0.3, 0.0))
    assert _choose(box, cube) == pytest.approx(0.7)


def _open_lid_gap(
    layout: Layout, shifts: dict[str, tuple[float, float]], box_id: str, other_id: str
) -> float:
    """Distance (m) between the open lid's rectangle and another object's footprint after separation."""
    import numpy as np
    from gsr.skills.assets import make_asset

    def at(o: PlacedObject) -> np.ndarray:
        return np.array(o.position[:2]) + np.array(shifts.get(o.id, (0.0, 0.0)))

    box = next(o for o in layout.objects if o.id == box_id)
    other = next(o for o in layout.objects if o.id == other_id)
    yaw = lid_side_yaw(layout, box)
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    model = make_asset(box.asset, box.size)
    art = model.articulations["lid"]
    lid_centre = at(box) + rot @ np.array([0.0, art.open - art.closed])
    half = np.array(model.extent[:2]) / 2
    o_half = np.array(make_asset(other.asset, other.size).extent[:2]) / 2
    local = np.abs(rot.T @ (at(other) - lid_centre))
    # the other object's footprint as a circle round its half-diagonal (conservative)
    return float(np.linalg.norm(np.maximum(local - half, 0.0))) - float(np.hypot(*o_half))


def test_separation_keeps_the_open_lids_side_free() -> None:
    from gsr.skills.build import HAND_CLEARANCE, separate_footprints

    box = PlacedObject(id="box", asset="box_with_lid", position=(0.0, 0.0, 0.0), size=BOX, yaw=0.0)
    # a cube where either end's open lid would lie over it: one side must be cleared
    cubes = [
        PlacedObject(id=f"c{i}", asset="cube", position=(0.02 * i, y, 0.0), size=(0.03, 0.03, 0.03))
        for i, y in enumerate((0.26, -0.27))
    ]
    layout = Layout(objects=(box, *cubes), table_size=(0.6, 1.2))
    shifts = separate_footprints(layout)
    # without the lid's room in the separation neither cube moves (both clear the closed box)
    assert shifts, "nothing moved"
    for c in cubes:
        assert _open_lid_gap(layout, shifts, "box", c.id) >= HAND_CLEARANCE - 0.025


def test_the_lid_does_not_open_into_a_fixture() -> None:
    box = PlacedObject(id="box", asset="box_with_lid", position=(0.0, 0.0, 0.0), size=BOX, yaw=0.0)
    # a cabinet 24 cm past the closed box's +y end (its centre 16 cm past the open lid): the lid sliding
    # that way would stop 2 cm short against it
    cab = PlacedObject(id="cab", asset="short_cabinet", position=(0.0, 0.56, 0.0), fixed=True)
    assert _angle(_choose(box, cab, table=(0.6, 1.6)), math.pi) < 1e-6
    cab_other = cab.model_copy(update={"position": (0.0, -0.56, 0.0)})
    assert _angle(_choose(box, cab_other, table=(0.6, 1.6)), 0.0) < 1e-6


def test_the_lids_room_does_not_push_the_box_behind_a_tall_fixture() -> None:
    """A lidded box the layout put into a cabinet's footprint, things on the table on its other side:
    keeping the open lid's room must not shove the box behind the cabinet (out of the arm's reach).
    Before the shadow check the box ended 19 cm along +y behind the cabinet's back corner."""
    from gsr.skills.build import in_shadow, separate_with_lids

    box = PlacedObject(id="box", asset="box_with_lid", position=(0.103, 0.258, 0.0), size=BOX, yaw=0.314)
    cab = PlacedObject(id="cab", asset="short_cabinet", position=(-0.055, 0.257, 0.0), fixed=True)
    small = [
        PlacedObject(id="m", asset="mug", position=(-0.109, -0.272, 0.0), size=(0.044, 0.044, 0.05)),
        PlacedObject(id="k", asset="milk", position=(-0.174, -0.421, 0.0), size=(0.05, 0.05, 0.065)),
        PlacedObject(id="p", asset="popcorn", position=(0.088, -0.406, 0.0), size=(0.04, 0.07, 0.065)),
    ]
    layout = Layout(objects=(box, cab, *small), table_size=(0.6, 1.2))
    shifts, sides = separate_with_lids(layout)
    assert "box" in shifts, "the box overlaps the cabinet: it must move"
    assert not in_shadow(layout, box, shifts["box"], [cab])
    assert set(sides) == {"box"}
