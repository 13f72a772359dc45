"""Objects in a tall fixture's shadow: the world build keeps them where the arm can pick them.

A layout sized for other assets may put an object just behind a fixture that is taller in our world
than in the benchmark's (GSR-Bench's short cabinet stands 23 cm, ours 32 cm with three drawers that
hold its mugs). From the robot's side the arm then reaches over the carcass and its wrist meets it from
every base spot: the pick is ``blocked`` before anything moves, whatever the plan. The build asks the
pick's own pre-motion check (the candidates of :func:`gsr.skills.grasping.pick_candidates`, a base spot
from which the arm reaches them touching nothing: :meth:`gsr.skills.motion.Motion.plan_base`) for every
movable object standing on the table behind a tall fixture; one that no candidate reaches is moved to
the nearest free table spot where one does, sideways out of the shadow first. Nothing moves when the
check passes, so layouts whose objects are reachable stay as they are.
"""

from __future__ import annotations

import numpy as np
from gsr.skills.arm_moves import APPROACH, transit_height
from gsr.skills.grasping import pick_candidates
from gsr.skills.motion import Motion
from gsr.skills.result import SkillError
from gsr.skills.world import SimObject, World

#: A fixture this tall (m) can hide what stands behind it from the arm.
TALL = 0.15
#: How far behind a fixture's back face (m) and beside its sides an object counts as in its shadow.
SHADOW_DEPTH, SHADOW_SIDE = 0.3, 0.12
#: Free room (m) an object moved out of a shadow keeps from fixtures (a hand's width) and other objects.
FIXTURE_ROOM, OBJECT_ROOM = 0.06, 0.015
#: Spots tried for one object (each costs a pick check with IK), and the step between them (m).
MAX_SPOTS, STEP = 6, 0.04
#: Pick candidates asked per check (best first; the wrist meeting a carcass does so for all of them).
CANDIDATES = 3


def _behind(world: World, obj: SimObject, fixture: SimObject) -> bool:
    """Whether ``obj`` stands behind ``fixture`` seen from the robot's side (world -x)."""
    lo, hi = world.body_aabb(fixture.body)
    c = (world.body_aabb(obj.body)[0] + world.body_aabb(obj.body)[1]) / 2
    if hi[2] - lo[2] < TALL:
        return False
    return hi[0] - 0.02 < c[0] < hi[0] + SHADOW_DEPTH and lo[1] - SHADOW_SIDE < c[1] < hi[1] + SHADOW_SIDE


def pickable(world: World, obj: SimObject) -> bool:
    """Whether some pick candidate of ``obj`` has a base spot from which the arm reaches it touching
    nothing (the check a pick makes before it moves); the robot is left as it was."""
    m = Motion(world)
    m.ignore = {obj.body}
    with world.robot.probe():
        centre = (world.body_aabb(obj.body)[0] + world.body_aabb(obj.body)[1]) / 2
        z = transit_height(world)
        for pos, quat, _opening in pick_candidates(world, obj)[:CANDIDATES]:
            above = (np.array([pos[0], pos[1], z]), quat)
            poses = [(pos, quat), (pos + np.array([0, 0, APPROACH]), quat), above]
            try:
                m.plan_base(centre, poses, clear=True, path=True)
                return True
            except SkillError:
                continue
        return False


def _free(world: World, obj: SimObject) -> bool:
    """Whether ``obj`` where it is now keeps its room from everything else and stays on the table."""
    import pybullet as p

    lo, hi = world.body_aabb(obj.body)
    tlo, thi = world.body_aabb(world.table_body)
    if lo[0] < tlo[0] + 0.01 or hi[0] > thi[0] - 0.01 or lo[1] < tlo[1] + 0.01 or hi[1] > thi[1] - 0.01:
        return False
    for o in world.objects.values():
        if o.id == obj.id:
            continue
        room = FIXTURE_ROOM if o.model.fixed else OBJECT_ROOM
        if p.getClosestPoints(obj.body, o.body, room, physicsClientId=world.client):
            return False
    return True


def _spots(world: World, obj: SimObject, fixture: SimObject) -> list[np.ndarray]:
    """Candidate centres, nearest first: beside the fixture's sides (out of the strip the arm reaches
    over it), at the object's depth and up to 8 cm nearer the robot."""
    import pybullet as p

    start = np.array(p.getBasePositionAndOrientation(obj.body, physicsClientId=world.client)[0][:2])
    lo, hi = world.body_aabb(fixture.body)
    olo, ohi = world.body_aabb(obj.body)
    half = float(ohi[1] - olo[1]) / 2
    sides = [float(lo[1]) - FIXTURE_ROOM - half, float(hi[1]) + FIXTURE_ROOM + half]
    out = [
        np.array([start[0] + dx, y + k * STEP * (1 if y > start[1] else -1)])
        for y in sides
        for k in range(4)
        for dx in (0.0, -STEP, -2 * STEP)
    ]
    return sorted(out, key=lambda c: float(np.linalg.norm(c - start)))


def keep_reachable(world: World) -> dict[str, tuple[float, float]]:
    """Move table-standing objects behind tall fixtures that no pick reaches to the nearest spot one
    does; returns id -> (dx, dy) for the objects moved (their graph relation, on the table, stays)."""
    import pybullet as p

    moved: dict[str, tuple[float, float]] = {}
    tall = [o for o in world.objects.values() if o.model.fixed]
    for obj in list(world.objects.values()):
        if obj.model.fixed or obj.placed.on not in (None, world.table_id):
            continue
        fixture = next((f for f in tall if _behind(world, obj, f)), None)
        if fixture is None or pickable(world, obj):
            continue
        pos, orn = p.getBasePositionAndOrientation(obj.body, physicsClientId=world.client)
        tried = 0
        for spot in _spots(world, obj, fixture):
            p.resetBasePositionAndOrientation(
                obj.body, (spot[0], spot[1], pos[2]), orn, physicsClientId=world.client
            )
            if not _free(world, obj):
                continue
            tried += 1
            if pickable(world, obj):
                moved[obj.id] = (round(float(spot[0] - pos[0]), 4), round(float(spot[1] - pos[1]), 4))
                break
            if tried >= MAX_SPOTS:
                break
        if obj.id not in moved:
            p.resetBasePositionAndOrientation(obj.body, pos, orn, physicsClientId=world.client)
    return moved
