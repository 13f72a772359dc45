"""Look-ahead probes (IK, straight-path and collision checks) set the arm's joints to configurations they
try; they must leave the moving arm exactly as it was: positions, velocities and motor targets.

Restoring only the measured positions (``Robot.reset``) zeroed the joints' velocities and re-targeted the
motors where the arm was at that instant: a discarded ``straight_path`` probe after an arrival changed the
rest of the episode (LIBERO KITCHEN_SCENE6: the mug ended on the microwave, not in it)."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from gsr.skills.motion import Motion
from gsr.skills.robot import ARM_FRONT, top_down


def _run_on(world, steps: int) -> np.ndarray:
    """Positions and velocities of the rail and arm joints after ``steps`` simulation steps."""
    world.step(steps)
    states = p.getJointStates(world.robot.body, world.robot.joints, physicsClientId=world.client)
    return np.array([[s[0], s[1]] for s in states])


@pytest.mark.physics
def test_probes_leave_a_moving_arm_as_it_was(bowl_world) -> None:
    world, robot = bowl_world, bowl_world.robot
    m = Motion(world)
    q0 = robot.q()
    target = np.array((*q0[:2], *ARM_FRONT))
    robot.hold(target)
    world.step(20)  # the arm is on its way: neither at rest nor at its target
    moving = p.getJointStates(robot.body, robot.joints, physicsClientId=world.client)
    assert max(abs(s[1]) for s in moving) > 0.01
    state = p.saveState(physicsClientId=world.client)
    undisturbed = _run_on(world, 60)

    p.restoreState(stateId=state, physicsClientId=world.client)
    robot.hold(target)
    pos = robot.ee_pose()[0]
    above = (pos + np.array([0.0, 0.0, 0.05]), top_down(0.0))
    below = (pos - np.array([0.0, 0.0, 0.05]), top_down(0.0))
    robot.ik(above[0], above[1], q0[:2])
    m.straight_path([above, below], robot.q())
    m.continuous_start([above, below], robot.q()[:2])
    m.first_hit(np.array((*q0[:2], *ARM_FRONT)))
    probed = _run_on(world, 60)
    assert np.allclose(probed, undisturbed, atol=1e-6), np.abs(probed - undisturbed).max()
