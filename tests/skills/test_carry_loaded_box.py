"""A box carried with a cube in it: the cube rides along instead of creeping to the far wall."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pybullet")


@pytest.mark.physics
def test_a_cube_in_a_box_set_aside_by_its_end_wall_stays_where_a_grasp_fits(snapshot_world) -> None:
    """gsrgen_sod_complex_11 (seed 0), from the state saved before the pick of ``yellow_box`` off
    ``blue_box`` (the recovery clearing the way to ``red_mug1``): the box, ``blue_cube1`` in its middle,
    is picked by its end wall and set aside on the table. With a position target that jumped once per
    waypoint the cube crept 9.4 cm along the box to its far end wall, where no grasp and no drag fits
    (the episode's pick of it was then ``blocked``); with the targets moved every simulation step it
    stays near the middle and is picked."""
    import pybullet as p
    from gsr.skills.library import DEFAULT_BUDGET, run_step
    from gsr.skills.recovery import set_aside

    from gsr.step import Step

    with snapshot_world("gsrgen_sod_complex_11", "sod_complex_11_before_yellow_box_pick.bullet") as world:
        box, cube = world.objects["yellow_box"], world.objects["blue_cube1"]

        def cube_in_box() -> np.ndarray:
            bp, bq = p.getBasePositionAndOrientation(box.body, physicsClientId=world.client)
            cp, _ = p.getBasePositionAndOrientation(cube.body, physicsClientId=world.client)
            inv = p.invertTransform(bp, bq)
            return np.array(p.multiplyTransforms(inv[0], inv[1], cp, (0, 0, 0, 1))[0])

        assert np.linalg.norm(cube_in_box()[:2]) < 0.01  # it starts in the box's middle
        assert run_step(world, Step("pick", ("yellow_box", "blue_box"))).ok
        put = set_aside(world, "yellow_box", [], DEFAULT_BUDGET)
        assert put.ok, put.message
        assert math.hypot(*cube_in_box()[:2]) < 0.03, f"the cube crept to {cube_in_box()[:2]} in the box"
        got = run_step(world, Step("pick", ("blue_cube1", "yellow_box")))
        assert got.ok, got.message
