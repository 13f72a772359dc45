"""Top-down grasps in clutter: where the Panda's hand fits, checked against walls and neighbours.

The hand is 20.4 cm long along its closing axis and 6.3 cm thick; its underside is 3.9 cm above the
grasp point and the fingertips 0.7 cm below it. Over a 3 cm cube on the floor of an 8.5 cm deep box
the hand's underside is below the wall tops, so the hand must fit *inside* the box: lying along the
box's long side, near its middle. Two physical facts widen what fits:

- the fingers are coupled (one motor, a rack) and close symmetrically about the hand's centre, so a
  hand centred up to 2 cm beside the object along the closing axis first slides it to the middle and
  then holds it: the hand may sit where the walls let it, not where the object is;
- a hand that grips only the object's upper part (at least 1.5 cm of finger on it) is higher and may
  clear the walls of a box whose contents stand tall enough (a 5 cm mug in an 8.5 cm box).

:func:`clear_grasps` searches yaws, offsets along and across the closing axis and grip heights, and
keeps the poses where a proxy of the hand (its collision hull's box, swept 15 cm up along the approach)
and of the open fingers touches nothing but the object; the arm itself is checked later, with IK, by
:meth:`gsr.skills.motion.Motion.plan_base`. Nothing here moves the robot or any object.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from gsr.skills.robot import GRIPPER, top_down
from gsr.skills.sim_graph import support_of
from gsr.skills.world import SimObject, World

#: The hand's collision hull in the grasp-point frame (z towards the fingertips, y the closing axis):
#: half sizes and z range of its box; it is checked at the grasp and at ``RISES`` above it (the vertical
#: approach and retreat).
PALM_HALF = (0.032, 0.104)
PALM_Z = (-0.131, -0.039)
RISES = (0.0, 0.04, 0.08, 0.12)
#: Tilts (rad) of the closing axis out of the horizontal: the hand's end over a near wall rises above it
#: (the fingers then square the object up against their pads as they close).
TILTS = (0.0, 0.2, -0.2, 0.35, -0.35, 0.45, -0.45)
#: One finger: half thickness (x), depth outward from its pad (y), z range.
FINGER_HALF_X, FINGER_DEPTH, FINGER_Z = 0.0105, 0.0264, (-0.0466, 0.0072)
#: The least length of finger on the object (m), measured down from its top.
MIN_OVERLAP = 0.015
FINGERTIP = 0.0072  # m: the fingertips are this far beyond the grasp point
#: The farthest the hand's centre may sit beside the object along the closing axis (m).
MAX_SLIDE = 0.02
SLIDES = (0.0, 0.005, -0.005, 0.01, -0.01, 0.015, -0.015, 0.02, -0.02)
#: Clearance the proxy keeps from everything but the object (m).
MARGIN = 0.001
#: Room (m) a release's hand must keep from everything: the descent stops 3 mm before a contact, and
#: the held object's re-measured position (the hand re-centred over the spot) is good to a few mm; a
#: finger passed down a hair outside a box's wall stops on its top.
RELEASE_MARGIN = 0.006


@dataclass(frozen=True)
class ClearGrasp:
    """A top-down hand pose that clears its surroundings: grasp point, orientation, opening, cost."""

    pos: np.ndarray
    quat: tuple[float, float, float, float]
    opening: float  # m between the open fingers (the slide's room included)
    cost: float
    slide: float  # m the closing fingers slide the object along the closing axis


class HandProxy:
    """Collision-only stand-ins for the palm and the open fingers (no mass, no visual, far away when idle)."""

    def __init__(self, world: World) -> None:
        import pybullet as p

        self.world = world
        c = world.client
        hz = (PALM_Z[1] - PALM_Z[0]) / 2
        palm = p.createCollisionShape(
            p.GEOM_BOX, halfExtents=[PALM_HALF[0], PALM_HALF[1], hz], physicsClientId=c
        )
        self._palm_offset = (0.0, 0.0, PALM_Z[1] - hz)
        self.palm = p.createMultiBody(0, palm, -1, (0, 0, -5), physicsClientId=c)
        self._fingers: dict[int, int] = {}
        self._bodies = [self.palm]

    def _finger_pair(self, opening: float) -> int:
        import pybullet as p

        key = round(opening * 1000)
        if key not in self._fingers:
            c = self.world.client
            hz = (FINGER_Z[1] - FINGER_Z[0]) / 2
            half = [FINGER_HALF_X, FINGER_DEPTH / 2, hz]
            y = opening / 2 + FINGER_DEPTH / 2
            zc = (FINGER_Z[0] + FINGER_Z[1]) / 2
            shape = p.createCollisionShapeArray(
                [p.GEOM_BOX, p.GEOM_BOX],
                halfExtents=[half, half],
                collisionFramePositions=[[0, y, zc], [0, -y, zc]],
                physicsClientId=c,
            )
            body = p.createMultiBody(0, shape, -1, (0, 0, -5), physicsClientId=c)
            self._fingers[key] = body
            self._bodies.append(body)
        return self._fingers[key]

    def hit(
        self,
        pos: np.ndarray,
        quat: tuple,
        opening: float,
        bodies: list[int],
        table: int,
        margin: float = MARGIN,
    ) -> bool:
        """Whether the fingers open to ``opening`` at this pose, or the palm there or straight above it
        (:data:`RISES`), come within ``margin`` of any of ``bodies`` (the table: only by going into it)."""
        import pybullet as p

        c = self.world.client
        palm_pos, _ = p.multiplyTransforms(list(pos), list(quat), self._palm_offset, (0, 0, 0, 1))
        fingers = self._finger_pair(opening)
        p.resetBasePositionAndOrientation(fingers, list(pos), quat, physicsClientId=c)
        try:
            for rise in RISES:
                if rise == 0.0:
                    part = fingers
                    if self._touches(part, bodies, table, margin):
                        return True
                at = (palm_pos[0], palm_pos[1], palm_pos[2] + rise)
                p.resetBasePositionAndOrientation(self.palm, at, quat, physicsClientId=c)
                if self._touches(self.palm, bodies, table, margin):
                    return True
            return False
        finally:
            for b in (self.palm, fingers):
                p.resetBasePositionAndOrientation(b, (0, 0, -5), (0, 0, 0, 1), physicsClientId=c)

    def _touches(self, part: int, bodies: list[int], table: int, margin: float = MARGIN) -> bool:
        import pybullet as p

        c = self.world.client
        if any(p.getClosestPoints(part, b, margin, physicsClientId=c) for b in bodies):
            return True
        return bool(p.getClosestPoints(part, table, -0.002, physicsClientId=c))

    def remove(self) -> None:
        """Take the proxies out of the world."""
        import pybullet as p

        for b in self._bodies:
            p.removeBody(b, physicsClientId=self.world.client)
        self._bodies, self._fingers = [], {}


def near_bodies(world: World, obj: SimObject, reach: float = 0.2) -> list[int]:
    """Bodies (the robot and the object excepted) whose boxes come within ``reach`` of the object's box."""
    import pybullet as p

    lo, hi = world.body_aabb(obj.body)
    found = p.getOverlappingObjects(
        [float(v) - reach for v in lo], [float(v) + reach for v in hi], physicsClientId=world.client
    )
    skip = {obj.body, world.robot.body, world.table_body}
    held = {o.body for o in world.objects.values() if o.id in world.welds}
    return sorted(
        {b for b, _ in (found or ()) if b not in skip and b not in held and b in _object_bodies(world)}
    )


def _object_bodies(world: World) -> set[int]:
    return {o.body for o in world.objects.values()}


def _tilted(quat: tuple, tilt: float) -> tuple[float, float, float, float]:
    """``quat`` turned by ``tilt`` about the hand's own x axis (its thickness): the closing axis tilts."""
    import pybullet as p

    if not tilt:
        return tuple(quat)  # type: ignore[return-value]
    turn = p.getQuaternionFromEuler((tilt, 0.0, 0.0))
    return tuple(p.multiplyTransforms((0, 0, 0), quat, (0, 0, 0), turn)[1])  # type: ignore[return-value]


def container_frame(world: World, obj: SimObject) -> tuple[np.ndarray, float, np.ndarray] | None:
    """``(centre, yaw, half sizes)`` of the interior ``obj`` lies in (a box's, a drawer's), world frame;
    None when it is in none."""
    rel, node = support_of(world, obj.id) or ("", "")
    found = world.interior_of(node) if rel == "in" else None
    if found is None:
        return None
    host, _, interior = found
    link = host.links[interior.link]
    centre = world.to_world(host.body, link, interior.center)
    return centre, world.yaw_of(host.body, link), np.array(interior.size) / 2


def _inside(world: World, obj: SimObject, host: SimObject) -> bool:
    """Whether ``obj``'s centre lies over ``host``'s footprint (the container holding it)."""
    lo, hi = world.body_aabb(obj.body)
    hlo, hhi = world.body_aabb(host.body)
    c = (lo + hi) / 2
    return bool(hlo[0] <= c[0] <= hhi[0] and hlo[1] <= c[1] <= hhi[1])


def container_yaw(world: World, obj: SimObject) -> float | None:
    """The heading of the interior ``obj`` is in (a box's, a drawer's), or None when it is in none."""
    frame = container_frame(world, obj)
    return None if frame is None else frame[1]


@dataclass(frozen=True)
class Drag:
    """A fingertip drag inside a container: hand pose on the object's top, and the way to move it."""

    start: np.ndarray
    quat: tuple[float, float, float, float]
    shift: np.ndarray  # m, world, horizontal


#: How far from the interior's middle (m, along its long side) a small solid must lie for a grasp to fit.
REACHABLE = 0.03
PRESS = 0.004  # m the lowest fingertip is set below the object's top: it holds the object by friction


def plan_drag(world: World, obj: SimObject, in_the_way: list[str] | None = None) -> list[Drag]:
    """Drags along a container's floor that bring a small solid to where a grasp fits: the closed
    fingertips press on its top and the hand, lying along the container and tilted so its end over a
    wall stays above it, moves it. Towards the middle when it lies near an end wall (a hand along the
    container fits there), otherwise 2 or 4 cm along either axis of the container to where
    :func:`clear_grasps` finds a grasp (away from a packed neighbour). Only moves whose way is free of
    other objects and whose hand proxy clears walls and neighbours, best first; none when the object
    is in no container. ``in_the_way`` (when given) collects the objects that stand on the way towards
    the middle, the one drag after which a grasp is known to fit (a mug packed by an end wall with
    another in the box's middle): moved, they would let the drag happen."""
    import pybullet as p

    frame = container_frame(world, obj)
    if frame is None or not obj.model.grasps:
        return []
    centre, yaw, half = frame
    long_yaw = yaw + (math.pi / 2 if half[1] > half[0] else 0.0)
    axis = np.array([math.cos(long_yaw), math.sin(long_yaw), 0.0])
    across = np.array([-axis[1], axis[0], 0.0])
    lo, hi = world.body_aabb(obj.body)
    here = (lo + hi) / 2
    along = float((here - centre) @ axis)
    site_def = obj.model.grasps[0]
    site = world.to_world(obj.body, obj.links[site_def.link], site_def.xyz)
    shifts: list[tuple[np.ndarray, bool]] = []  # (shift, whether a grasp is known to fit after it)
    if abs(along) > REACHABLE:
        shifts.append((-axis * (along - math.copysign(REACHABLE * 0.5, along)), True))
    shifts += [(d * u * sign, False) for d in (0.02, 0.04) for u in (axis, across) for sign in (1, -1)]
    host_bodies = {o.body for o in world.objects.values() if o.model.interiors and _inside(world, obj, o)}
    others = _object_bodies(world) - {obj.body} - host_bodies
    movable = {o.body for o in world.objects.values() if not o.model.fixed} & others
    half_xy = (hi[:2] - lo[:2]) / 2 + 0.003
    bodies = near_bodies(world, obj, reach=0.3)
    out: list[Drag] = []
    for shift, known in shifts:
        # the object's way: its footprint swept, 3 mm apart from everything else in the container,
        # and inside the container's interior
        a, b = here, here + shift
        # inside the interior (its floor's half sizes, not its height), or no farther out than now (a
        # mug's box, its handle in it, may stand out: a drag along the box keeps its place across)
        if abs(float((b - centre) @ axis)) > max(
            max(half[:2]) - half_xy.max(), abs(float((a - centre) @ axis))
        ) or abs(float((b - centre) @ across)) > max(
            min(half[:2]) - half_xy.max(), abs(float((a - centre) @ across))
        ):
            continue
        sweep_lo = [min(a[0], b[0]) - half_xy[0], min(a[1], b[1]) - half_xy[1], float(lo[2]) + 0.002]
        sweep_hi = [max(a[0], b[0]) + half_xy[0], max(a[1], b[1]) + half_xy[1], float(hi[2])]
        found = p.getOverlappingObjects(sweep_lo, sweep_hi, physicsClientId=world.client) or ()
        # the swept boxes overlap (a broad test: a mug's box holds its handle): the object's own shape
        # moved along the way says which really stand on it
        blocking = _on_the_way(world, obj, shift, sorted({bd for bd, _ in found if bd in others}))
        if blocking:
            if known and in_the_way is not None:
                by_body = {o.body: o.id for o in world.objects.values()}
                in_the_way += sorted({by_body[bd] for bd in blocking} - set(in_the_way))
            continue
        if not known and not clear_grasps(world, obj, site + shift, site_def.width, limit=1):
            continue
        proxy = HandProxy(world)
        hand_in: set[int] = set()  # movable neighbours the hand alone meets on a drag known to help
        try:
            for tilt in DRAG_TILTS:
                quat = _tilted(top_down(long_yaw), tilt)
                # the lowest closed fingertip (the fingers meet at the grasp point) on the object's top
                start = np.array([here[0], here[1], float(hi[2]) + FINGERTIP * math.cos(tilt) - PRESS])
                ends = (start, start + shift, start + shift * 0.5)
                if not any(proxy.hit(p_, quat, 0.0, bodies, world.table_body) for p_ in ends):
                    out.append(Drag(start, quat, shift))
                elif known and in_the_way is not None and not out:
                    hand_in |= _hand_meets(proxy, ends, quat, bodies, movable, world.table_body)
        finally:
            proxy.remove()
        if not out and hand_in:
            # the hand (not the object's way) meets a packed neighbour (a mug beside the cube's way)
            # at every tilt where walls alone let it drag: named, it can be set aside first
            by_body = {o.body: o.id for o in world.objects.values()}
            in_the_way += sorted({by_body[bd] for bd in hand_in} - set(in_the_way))
        if len(out) >= 4:
            break
    return out


#: Tilts (rad) of a drag's hand about its thickness axis: its end over the near wall stays above it.
DRAG_TILTS = (0.2, -0.2, 0.35, -0.35, 0.45, -0.45)


def _hand_meets(
    proxy: HandProxy, ends: tuple, quat: tuple, bodies: list[int], movable: set[int], table: int
) -> set[int]:
    """The movable ``bodies`` a drag's hand meets at one of ``ends`` when everything else (walls,
    fixtures) lets it pass there; empty when something unmovable is in the hand's way too."""
    fixed = [b for b in bodies if b not in movable]
    if any(proxy.hit(p_, quat, 0.0, fixed, table) for p_ in ends):
        return set()
    return {b for b in bodies if b in movable and any(proxy.hit(p_, quat, 0.0, [b], table) for p_ in ends)}


#: Steps (m) along a drag's way at which the object's own shape is checked against its neighbours.
WAY_STEP = 0.01


def _on_the_way(world: World, obj: SimObject, shift: np.ndarray, bodies: list[int]) -> set[int]:
    """Those of ``bodies`` that ``obj``, moved by ``shift`` along the floor (checked every
    :data:`WAY_STEP`), would come within 1 mm of, nearer than it stands now (a neighbour it touches
    and moves away from is not on its way). The object is put back exactly; nothing else moves."""
    import pybullet as p

    if not bodies:
        return set()
    cid = world.client

    def gaps() -> dict[int, float]:
        out = {}
        for b in bodies:
            pts = p.getClosestPoints(obj.body, b, 0.01, physicsClientId=cid)
            out[b] = min((q[8] for q in pts), default=0.01)
        return out

    pos, quat = p.getBasePositionAndOrientation(obj.body, physicsClientId=cid)
    start = gaps()
    hit: set[int] = set()
    n = max(1, math.ceil(float(np.linalg.norm(shift)) / WAY_STEP))
    try:
        for i in range(1, n + 1):
            at = np.asarray(pos) + np.asarray(shift) * i / n
            p.resetBasePositionAndOrientation(obj.body, at.tolist(), quat, physicsClientId=cid)
            hit |= {b for b, d in gaps().items() if d < 0.001 and d < start[b] - 0.0005}
    finally:
        p.resetBasePositionAndOrientation(obj.body, pos, quat, physicsClientId=cid)
    return hit


def _closing_yaws(obj: SimObject, body_yaw: float, walls: float | None) -> list[tuple[float, float]]:
    """World closing yaws to try with a misalignment cost: a mug only across its body (never on its
    handle, at +90 deg), a square solid every 15 deg and along a container's walls (``walls``: its
    heading), face-aligned best; others along both faces."""
    sx, sy = obj.model.extent[:2]
    if obj.model.name == "mug":
        return [(body_yaw + math.radians(d), math.radians(abs(d))) for d in (0, 15, -15, 30, -30)]
    if abs(sx - sy) < 1e-6:
        turns = [math.radians(d) for d in range(0, 180, 15)]
        if walls is not None:
            turns = [walls - body_yaw, walls - body_yaw + math.pi / 2, *turns]
        out = []
        for t in turns:
            off = abs(((t + math.pi / 4) % (math.pi / 2)) - math.pi / 4)  # to the nearest face normal
            out.append((body_yaw + t, off))
        return out
    return [(body_yaw, 0.0), (body_yaw + math.pi / 2, 0.0)]


def clear_grasps(
    world: World, obj: SimObject, site: np.ndarray, site_width: float, limit: int = 8
) -> list[ClearGrasp]:
    """Top-down grasps of a small object held whole (a cube, a package, a small mug) around its grasp
    site ``site`` (world) whose hand and open fingers clear walls and neighbours, cheapest first (no
    slide, centred, face-aligned, low grip). ``site_width``: the object's width between the fingers
    at the site (a mug's body, not its handle)."""
    hi = world.body_aabb(obj.body)[1]
    centre = np.asarray(site, dtype=float)
    site_z = float(centre[2])
    body_yaw = world.yaw_of(obj.body)
    sx, sy = obj.model.extent[:2]
    top = float(hi[2])
    z_hi = top - MIN_OVERLAP + FINGERTIP
    heights = sorted({round(site_z, 4), round((site_z + z_hi) / 2, 4), round(z_hi, 4)})
    heights = [z for z in heights if z >= site_z - 1e-6] or [site_z]
    bodies = near_bodies(world, obj)
    table = world.table_body
    proxy = HandProxy(world)
    found: list[ClearGrasp] = []
    try:
        for yaw, misalign in _closing_yaws(obj, body_yaw, container_yaw(world, obj)):
            t = yaw - body_yaw
            along = abs(math.cos(t)) * sx + abs(math.sin(t)) * sy  # the object's width between the fingers
            if obj.model.name == "mug":
                along = site_width
            e1 = np.array([math.cos(yaw), math.sin(yaw), 0.0])  # closing axis
            e2 = np.array([-e1[1], e1[0], 0.0])
            level = top_down(yaw)
            # the pads stay on the object across the closing axis (on a round mug, near its axis)
            across_room = max(
                0.0, site_width / 2 - 0.014 if obj.model.name == "mug" else min(sx, sy) / 2 - 0.006
            )
            for tilt, slide in itertools.product(TILTS, SLIDES):
                width = along + 2 * abs(slide)
                opening = width + 0.012
                if abs(slide) > MAX_SLIDE or opening > GRIPPER.open_width:
                    continue
                if abs(tilt) > 0.25 and obj.model.name == "mug":
                    continue  # a round body would roll out of steeply tilted pads
                quat = _tilted(level, tilt)
                for across in (0.0, across_room, -across_room):
                    spot = centre + slide * e1 + across * e2
                    grip = next(
                        (
                            z
                            for z in heights
                            if not proxy.hit(np.array([spot[0], spot[1], z]), quat, opening, bodies, table)
                        ),
                        None,
                    )
                    if grip is None:
                        continue
                    cost = 10 * abs(slide) + 10 * abs(across) + misalign + 3 * (grip - site_z) + 2 * abs(tilt)
                    found.append(ClearGrasp(np.array([spot[0], spot[1], grip]), quat, opening, cost, slide))
                    break  # centred across when that fits
    finally:
        proxy.remove()
    found.sort(key=lambda g: g.cost)
    return found[:limit]


def hand_clear_at(
    world: World,
    held: SimObject,
    spot: np.ndarray,
    turn: float = 0.0,
    lift: float = 0.0,
    margin: float = MARGIN,
) -> bool:
    """Whether the hand, holding ``held`` as it does now (the wrist turned by ``turn`` about the
    vertical), keeps ``margin`` from everything else when the object's bottom centre is set ``lift``
    above ``spot`` (the release point, or a point above it a release may stop at, and the vertical way
    down to it)."""
    import pybullet as p

    ee, quat = world.robot.ee_pose()
    lo, hi = world.body_aabb(held.body)
    offset = ee - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    if turn:
        c, s = math.cos(turn), math.sin(turn)
        offset = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
        quat = p.multiplyTransforms((0, 0, 0), p.getQuaternionFromEuler((0, 0, turn)), (0, 0, 0), quat)[1]
    pos = np.asarray(spot, dtype=float) + offset + np.array([0.0, 0.0, 0.012 + lift])
    opening = min(GRIPPER.open_width, world.robot.finger_width() + 0.016)
    bodies = sorted(_object_bodies(world) - {held.body})
    proxy = HandProxy(world)
    try:
        return not proxy.hit(
            pos, tuple(float(v) for v in quat), opening, bodies, world.table_body, margin=margin
        )
    finally:
        proxy.remove()


def hand_clear(world: World, obj: SimObject, pos: np.ndarray, quat: tuple, opening: float) -> bool:
    """Whether a grasp of ``obj`` at ``pos`` / ``quat`` with the fingers open to ``opening`` keeps the
    hand and fingers (and the hand straight above, the way in) off everything but ``obj``."""
    proxy = HandProxy(world)
    try:
        return not proxy.hit(np.asarray(pos), quat, opening, near_bodies(world, obj), world.table_body)
    finally:
        proxy.remove()


def graspable_at(world: World, obj: SimObject, spot: np.ndarray, yaw: float | None = None) -> bool:
    """Whether a later pick would find a top-down grasp (:func:`clear_grasps`) of ``obj``, an object
    held whole (a cube, a package, a small mug), if it stood with its bottom centre at ``spot``, turned
    to ``yaw`` (default: as now). What a placement into a deep box needs of its spot: a cube let go
    against a wall fits no hand that must reach in past 8.5 cm walls. The object is moved there for
    the check and put back exactly; nothing else moves. Objects not held whole are not judged (True)."""
    import pybullet as p

    whole = [g for g in obj.model.grasps if math.hypot(*g.xyz[:2]) < 1e-6]
    if not whole:
        return True
    cid = world.client
    pos, quat = p.getBasePositionAndOrientation(obj.body, physicsClientId=cid)
    lo, hi = world.body_aabb(obj.body)
    # the base frame relative to the bottom centre, turned with the object
    off = np.asarray(pos) - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    new_quat = quat
    if yaw is not None:
        roll, pitch, now = p.getEulerFromQuaternion(quat)
        new_quat = p.getQuaternionFromEuler((roll, pitch, yaw))
        c, s = math.cos(yaw - now), math.sin(yaw - now)
        off = np.array([c * off[0] - s * off[1], s * off[0] + c * off[1], off[2]])
    target = np.asarray(spot, dtype=float) + off
    p.resetBasePositionAndOrientation(obj.body, target.tolist(), new_quat, physicsClientId=cid)
    try:
        site = world.to_world(obj.body, obj.links[whole[0].link], whole[0].xyz)
        return bool(clear_grasps(world, obj, site, whole[0].width, limit=1))
    finally:
        p.resetBasePositionAndOrientation(obj.body, pos, quat, physicsClientId=cid)


#: A rim pinch (:func:`rim_pinches`): how far the fingertips go down inside a small mug's rim (m), the
#: room each open finger keeps from the wall (m), how far the hand's centre sits outward of the wall's
#: middle (m: the inner finger, thicker up its length, then keeps off the far wall of a 2.8 cm interior;
#: measured on GSR-Bench's 4.4 cm mug: 6 mm of room centred left a finger on the far wall and the
#: descent 5 mm high, and the mug slipped out as it rose), and how far from the handle's direction
#: (rad) the pinch must be (the outer finger would meet the handle, which the proxy does not check:
#: it is the object's own).
PINCH_DEPTH = 0.012
PINCH_ROOM = 0.004
PINCH_OUTSET = 0.002
PINCH_HANDLE_GAP = math.radians(50)
#: Margins (m) a pinch's proxy is tried at: one that keeps more room from walls and neighbours is
#: preferred (the rim point that faces the most free room).
PINCH_MARGINS = (0.015, 0.008, MARGIN)


def rim_segments(obj: SimObject) -> list[tuple[float, float, float]]:
    """``(angle, radius, thickness)`` of the rim wall's segments in the object's base frame: the box
    shapes of its base link that stand radially round its axis (a mug's or cup's ring), none for a solid."""
    link = next((lk for lk in obj.model.links if lk.name == "base"), None)
    if link is None:
        return []
    out = []
    for s in link.shapes:
        if s.kind != "box" or not s.collide:
            continue
        x, y, _ = s.xyz
        radius = math.hypot(x, y)
        if radius < 1e-3:
            continue
        angle = math.atan2(y, x)
        if abs(math.sin(angle - s.rpy[2])) > 1e-3:  # not radial: a handle, a tab
            continue
        out.append((angle, radius, float(s.size[0])))
    return out


def rim_pinches(world: World, obj: SimObject, limit: int = 6) -> list[ClearGrasp]:
    """Top-down grasps that pinch a small hollow object's rim wall (a GSR-Bench 4.4 cm mug): the closing
    axis radial, one finger inside the rim and one outside, the fingertips :data:`PINCH_DEPTH` down.

    A mug held whole needs a finger's room beyond its body on both sides of the closing axis, which a
    box wall or a packed neighbour takes; a pinch needs it on one side only (the inner finger is in the
    mug's own interior) and may close along any radius but the handle's, so it fits where the whole-body
    grasps do not (a mug by a box's end wall, a mug beside a mug). Of the rim points whose hand and outer
    finger clear walls and neighbours (the proxy), those keeping the most room come first."""
    segments = rim_segments(obj)
    handle = obj.model.keypoints.get("handle")
    if not segments or handle is None or obj.model.name != "mug":
        return []
    import pybullet as p

    hx, hy = handle[1][0], handle[1][1]
    handle_angle = math.atan2(hy, hx)
    pos, quat = p.getBasePositionAndOrientation(obj.body, physicsClientId=world.client)
    top = float(world.body_aabb(obj.body)[1][2])
    z = top - PINCH_DEPTH + FINGERTIP
    bodies = near_bodies(world, obj)
    proxy = HandProxy(world)
    found: list[ClearGrasp] = []
    try:
        for angle, radius, thickness in segments:
            off = math.remainder(angle - handle_angle, 2 * math.pi)
            if abs(off) < PINCH_HANDLE_GAP:
                continue
            point, _ = p.multiplyTransforms(
                pos, quat, (radius * math.cos(angle), radius * math.sin(angle), 0), (0, 0, 0, 1)
            )
            rim = np.array(point)
            outward = rim[:2] - np.array(pos[:2])
            yaw = math.atan2(outward[1], outward[0])
            out = PINCH_OUTSET * np.array([math.cos(yaw), math.sin(yaw)])
            grasp = np.array([rim[0] + out[0], rim[1] + out[1], z])
            opening = thickness + 2 * PINCH_ROOM
            hand = top_down(yaw)
            for rank, margin in enumerate(PINCH_MARGINS):
                if not proxy.hit(grasp, hand, opening, bodies, world.table_body, margin=margin):
                    found.append(ClearGrasp(grasp, hand, opening, 1.0 + rank - abs(off) * 1e-3, 0.0))
                    break
    finally:
        proxy.remove()
    found.sort(key=lambda g: g.cost)
    return found[:limit]
