"""The bare table's release-spot search (issue 20): a spot where the whole hand is clear and the arm
reaches is preferred over the first free spot near the hand; the old choice is the fallback.

The scene is a generated GSR-Bench General cell (shipped code, no third-party data).
"""

from __future__ import annotations

import numpy as np
import pytest
from gsr.benchmarks.suites import get_suite
from gsr.skills.build import build_world
from gsr.skills.grasping import target_point
from gsr.skills.hand_clearance import hand_clear_at
from gsr.skills.sim_graph import support_of

pytestmark = pytest.mark.physics


def _task(task_id: str):
    return next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id == task_id)


def test_the_table_spot_is_one_the_arm_reaches_with_the_hand_clear() -> None:
    from gsr.skills.library import run_step

    from gsr.step_grammar import parse_step_text

    with build_world(_task("gsrgen_ss_general_00"), seed=0) as world:
        cube = next(
            o for o in world.objects.values() if "cube" in o.id and support_of(world, o.id) == ("on", "table")
        )
        result = run_step(world, parse_step_text(f"(pick {cube.id} table)"))
        assert result.ok, result.message
        table_z = world.body_aabb(world.table_body)[1][2]
        ee = world.robot.ee_pose()[0][:2]

        first = target_point(world, "table", cube, "on")
        assert first[2] <= table_z + 1e-6
        assert hand_clear_at(world, cube, first)

        # an arm that reaches nothing within 30 cm of the hand: a hand-clear spot further away, not
        # the first free one near the hand
        asked: list[np.ndarray] = []

        def far_only(spot: np.ndarray, turn: float) -> bool:
            asked.append(spot)
            return float(np.linalg.norm(spot[:2] - ee)) > 0.3

        far = target_point(world, "table", cube, "on", reachable=far_only)
        assert asked, "the reach was never asked about"
        assert far[2] <= table_z + 1e-6
        assert float(np.linalg.norm(far[:2] - ee)) > 0.3
        assert hand_clear_at(world, cube, far)

        # an arm that reaches nowhere: the old choice, not an error
        none = target_point(world, "table", cube, "on", reachable=lambda spot, turn: False)
        assert np.allclose(none, first)
