"""Releases into a box whose middle is taken (issue 20, GSR-Bench Complex).

SOD Complex 14: a 3 cm cube goes into GSR-Bench's 8.5 cm deep box with a mug standing in its middle.
The packing's spot is by an end wall, where the open finger meets the wall top and the descent stops
7.8 cm high. The retry's spot search looked only for spots where the hand reaches the release point
itself: over a cube on the box floor the 20 cm hand must then lie inside the box, which the mug
forbids everywhere. A release is also good up to ``MAX_DROP`` above its point, so the search takes a
spot where the hand clears everything a few centimetres higher.
"""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from gsr.benchmarks.suites import get_suite
from gsr.skills import hand_clearance as hc
from gsr.skills.build import build_world
from gsr.skills.grasping import MAX_DROP
from gsr.skills.library import run_step
from gsr.skills.sim_graph import support_of

from gsr.step_grammar import parse_step_text

pytestmark = pytest.mark.physics


def _task(task_id: str):
    return next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id == task_id)


def _move_with(world, names: list[str], dx: float, dy: float) -> None:
    """Shift bodies (a box and what it carries) together across the table."""
    for n in names:
        body = world.objects[n].body
        pos, quat = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
        p.resetBasePositionAndOrientation(
            body, [pos[0] + dx, pos[1] + dy, pos[2]], quat, physicsClientId=world.client
        )
    for _ in range(120):
        p.stepSimulation(physicsClientId=world.client)


def test_a_cube_goes_into_a_deep_box_whose_middle_a_mug_takes(monkeypatch) -> None:
    from gsr.skills import grasping

    with build_world(_task("gsrgen_sod_complex_14"), seed=0) as world:
        # the plan's first steps, shortened: the yellow box (with the cube it carries) off the red box
        # to the free far end of the desk, where the episode's own set-down put it
        ylo, yhi = world.body_aabb(world.objects["yellow_box"].body)
        centre = (ylo + yhi) / 2
        _move_with(world, ["yellow_box", "blue_cube2"], 0.03 - float(centre[0]), 0.46 - float(centre[1]))
        assert support_of(world, "yellow_box") == ("on", "table")
        assert support_of(world, "yellow_mug1") == ("in", "red_box")
        got = run_step(world, parse_step_text("(pick red_cube1 table)"))
        assert got.ok, got.message
        cube = world.objects["red_cube1"]
        mlo, mhi = world.body_aabb(world.objects["yellow_mug1"].body)
        found: list = []
        real = grasping.hand_clear_release

        def spy(*args, **kwargs):
            out = real(*args, **kwargs)
            found.append(out)
            if out is not None:
                # the hand clears there no higher than a release may be let go, the wrist turned so
                spot, turn = out
                assert any(
                    hc.hand_clear_at(world, cube, spot, turn, lift=h, margin=hc.RELEASE_MARGIN)
                    for h in grasping.RELEASE_LIFTS
                )
                assert max(grasping.RELEASE_LIFTS) < MAX_DROP - 0.01
                gap = np.abs(spot[:2] - (mlo[:2] + mhi[:2]) / 2) - (mhi[:2] - mlo[:2]) / 2
                assert float(gap.max()) > 0.015  # off the mug's footprint
            return out

        monkeypatch.setattr(grasping, "hand_clear_release", spy)
        # the packing's spot is by an end wall, where the open finger meets the wall top: the release
        # stops high, and the retry finds a spot (before: none, "the hand stops 0.078 m above")
        done = run_step(world, parse_step_text("(place_in red_cube1 red_box)"))
        assert found and found[0] is not None, "the release did not stop high, or no spot was found"
        assert done.ok, done.message
        assert support_of(world, "red_cube1") == ("in", "red_box")
        assert support_of(world, "yellow_mug1") == ("in", "red_box")
