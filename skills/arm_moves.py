"""Arm moves shared by the pick-and-place skills (``grasping``) and the articulated ones (``articulated``).

A safe travel height over the table, a straight lift to it, and the approach distance above a grasp
or release point. They live below both skill modules so that neither imports the other for them
(``grasping`` still uses ``articulated``'s roofed-container push-in; ``articulated`` imports only this).
"""

from __future__ import annotations

import numpy as np
from gsr.skills.motion import Motion
from gsr.skills.result import SkillError
from gsr.skills.world import World

TRANSIT_CLEARANCE = 0.08  # m above the tallest thing under the path
APPROACH = 0.1  # m above a grasp or release point


def transit_height(world: World, extra: float = 0.0, exclude: tuple[str, ...] = ()) -> float:
    """A safe travel height: above every object on the table plus clearance (and a held object's length).

    Fixtures taller than 45 cm (shelves, tall cabinets) are left out: the arm works beside them.
    """
    tops = [
        world.body_aabb(o.body)[1][2]
        for o in world.objects.values()
        if o.id not in exclude and (not o.model.fixed or o.model.extent[2] < 0.45)
    ]
    return max([world.layout.table_height + 0.1, *tops]) + TRANSIT_CLEARANCE + extra


def lift(m: Motion, z: float) -> None:
    """Raise the hand straight up to height ``z`` (no-op when it is already there), orientation kept."""
    pos, quat = m.pose()
    if pos[2] >= z - 0.005:
        return
    top = np.array([pos[0], pos[1], z])
    try:
        m.solve(top, quat)
    except SkillError:  # too high for the arm from here: bring the base under the hand first
        try:
            m.park_for(top, poses=[(top, quat)])
        except SkillError:
            # out of reach from every base spot (a tall stack somewhere sets the transit height): the
            # highest height the arm reaches here; the moves that follow are collision-checked anyway
            for lower in np.arange(z - 0.04, pos[2], -0.04):
                top = np.array([pos[0], pos[1], lower])
                try:
                    m.solve(top, quat)
                    break
                except SkillError:
                    continue
            else:
                return
    # an arm left against a joint limit (a tilted hand at the wrist's stop) re-branches in joint space
    m.move_rebranch((top, quat), check=False)
