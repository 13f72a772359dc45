"""Which side a lidded box's sliding lid opens to: the clearest one, never far past the near edge."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest
from gsr.skills.assets import make_asset
from gsr.skills.build import _lid_clear_yaw

from gsr.task_spec import Layout, PlacedObject

BOX = (0.17, 0.25, 0.085)


def _choose(box: PlacedObject, *others: PlacedObject, table: tuple[float, float] = (0.6, 1.2)) -> float:
    layout = Layout(objects=(box, *others), table_size=table)
    world = SimpleNamespace(layout=layout, adjusted={})
    model = make_asset(box.asset, box.size, None)
    return _lid_clear_yaw(world, box, model)  # type: ignore[arg-type]


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
