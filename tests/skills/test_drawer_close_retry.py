"""A drawer's second push starts with the hand resting on that drawer (issue 20, GSR-Bench GCG 14).

A close whose first push ends short (here 9 cm out, a milk carton inside) is pushed once more. The
first stroke's retreat leaves the hand low at the drawer's front, a finger on it; the second stroke's
lift could raise it only 1.7 cm, the base then slid 7 cm forward with the arm held still (only the
base's own links are checked), and the joint-space approach started in contact with the very drawer
being closed: ``blocked`` "joint move collides with short_cabinet (drawer_2) at the left finger".

The simulator state is the one saved at the end of that first push (``data/``, a PyBullet snapshot
written by ``p.saveBullet`` in ``gsrgen_gg_general_14``, seed 0, after its steps 1-8 and the close's
first stroke), so the test does not depend on how the earlier steps' grasps went.
"""

from __future__ import annotations

import pytest
from gsr.skills.library import run_step
from gsr.skills.motion import Motion

from gsr.step_grammar import parse_step_text

pytestmark = pytest.mark.physics


def test_a_second_push_starts_clear_of_the_drawer_it_closes(snapshot_world) -> None:
    with snapshot_world("gsrgen_gg_general_14", "gcg_general_14_after_short_push.bullet") as world:
        world.robot.command_gripper(0.0)  # a push is made with closed fingers
        cab = world.objects["short_cabinet"]
        # the situation: the drawer 9 cm out, a finger of the hand resting on it, the milk inside
        assert 0.08 < world.joint_position(cab, "drawer_2") < 0.1
        hit = Motion(world).first_hit(world.robot.q())
        assert hit is not None and "short_cabinet (drawer_2)" in hit[0]
        result = run_step(world, parse_step_text("(close short_cabinet/drawer_high)"))
        assert result.ok, result.message
        assert world.joint_position(cab, "drawer_2") < 0.02
