"""Pick and place with friction grasps: approach from above, close the fingers with force, lift, check.

Grasp sites come from the asset model; round and hollow objects get sites around their rim and the one
nearest the robot that the arm can reach without collision is taken. Placement computes where the
held object's bottom must go (the grasp offset is measured, not assumed) and releases 1 cm above the
surface. Every phase checks the simulator: fingers closed on something, object rises with the hand,
object rests where the step says after release.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np
from gsr.skills.arm_moves import APPROACH, lift, transit_height
from gsr.skills.articulated import push_in, roofed_opening
from gsr.skills.asset_model import GraspSite
from gsr.skills.hand_clearance import (
    RELEASE_MARGIN,
    clear_grasps,
    graspable_at,
    hand_clear,
    hand_clear_at,
    plan_drag,
    rim_pinches,
)
from gsr.skills.motion import Motion
from gsr.skills.packing import packed_spot
from gsr.skills.result import Failure, SkillError
from gsr.skills.robot import GRIPPER, angled, top_down
from gsr.skills.sim_graph import interior_boxes, support_of
from gsr.skills.surfaces import hand_crowding, surface_spot, uncrowded_turn
from gsr.skills.world import SimObject, World

MAX_DROP = 0.06  # m: the most a placed object may be let go above its release point

#: Rectangles on the table: (centre xy, half sizes xy).
Rects = tuple[tuple[np.ndarray, np.ndarray], ...] | list[tuple[np.ndarray, np.ndarray]]


def _rim_sites(site: GraspSite, obj: SimObject) -> list[GraspSite]:
    """A rim/wall site and its copies around the object's z axis (hollow objects), else the site (and +90 deg)."""
    x, y, z = site.xyz
    r = math.hypot(x, y)
    if r < 1e-6:
        sx, sy = obj.model.extent[:2]
        if obj.model.name == "mug":
            # a mug held whole closes across its body, never on its handle (at +90 deg): up to 30 deg off x
            turns = [0.0, math.pi, math.pi / 6, -math.pi / 6, math.pi * 5 / 6, -math.pi * 5 / 6]
        elif abs(sx - sy) < 1e-6 and math.hypot(sx, sy) < 0.06:
            # a small square solid (GSR-Bench's 3 cm cube): the face-aligned grasps first; the hand is
            # 22 cm long along its closing axis, so beside a box wall at 45 deg to the cube's faces both
            # collide, and a grasp across the corners (the parallel fingers square the cube up) is tried
            turns = [0.0, math.pi / 2, math.pi / 4, -math.pi / 4, math.pi / 8, -math.pi / 8, 3 * math.pi / 8]
        else:
            turns = [0.0, math.pi / 2]
        return [
            GraspSite(
                site.link,
                site.xyz,
                site.yaw + t,
                site.approach,
                max(site.width, abs(math.cos(t)) * sx + abs(math.sin(t)) * sy) if t else site.width,
            )
            for t in turns
        ]
    base = math.atan2(y, x)
    n = 8 if obj.model.name in ("bowl", "plate", "mug", "cup", "ramekin", "pan") else 4
    radii = [r] * n
    if n == 4:
        # a rectangular box's four walls: each copy sits on its own wall, inset from it as the model's
        # site is from its wall (GSR-Bench's 17 x 25 cm box: a copy at the first wall's radius would
        # stand 4.5 cm inside the short walls and close on nothing, or on what the box holds)
        sx, sy = obj.model.extent[:2]

        def half_extent(angle: float) -> float:
            return (abs(math.cos(angle)) * sx + abs(math.sin(angle)) * sy) / 2

        inset = half_extent(base) - r
        if inset < 0:
            return [site]  # a fin or tab outside the walls (a lidded box's grip fin): only where it is
        radii = [max(half_extent(base + math.pi * k / 2) - inset, 0.0) for k in range(n)]
    return [
        GraspSite(
            site.link,
            (
                radii[k] * math.cos(base + 2 * math.pi * k / n),
                radii[k] * math.sin(base + 2 * math.pi * k / n),
                z,
            ),
            site.yaw + 2 * math.pi * k / n,
            site.approach,
            site.width,
        )
        for k in range(n)
    ]


def site_pose(world: World, obj: SimObject, site: GraspSite) -> tuple[np.ndarray, float]:
    link = obj.links[site.link]
    pos = world.to_world(obj.body, link, site.xyz)
    return pos, world.yaw_of(obj.body, link) + site.yaw


TILT = 0.5  # rad from vertical: a hand leaning away from a tall neighbour keeps its palm off it
MAX_CLOSING = 0.075  # m: the widest object the 8 cm gripper closes on with room to spare
NEAR = 0.12  # m: neighbours closer than this (footprint to grasp centre) shape the grasp candidates


def walls_near(world: World, obj: SimObject, z: float) -> list[float]:
    """World yaws pointing from ``obj`` to the nearest face of each neighbour taller than ``z``."""
    lo, hi = world.body_aabb(obj.body)
    c = (lo[:2] + hi[:2]) / 2
    out = []
    for o in world.objects.values():
        if o.id == obj.id or support_of(world, o.id) == ("held", ""):
            continue
        for centre, yaw, half, top in object_footprints(world, o):
            if top < z:
                continue
            rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
            local = rot.T @ (c - centre)
            d = local - np.clip(local, -half, half)
            dist = float(np.linalg.norm(d))
            if 1e-6 < dist < NEAR:
                towards = rot @ (-d / dist)
                out.append(math.atan2(towards[1], towards[0]))
    return out


def object_footprints(world: World, o: SimObject) -> list[tuple[np.ndarray, float, np.ndarray, float]]:
    """(centre, yaw, half sizes, top) of an object's footprint; an open sliding lid apart from its box.

    A lid slid open lies beside its box at rim height, a wall of its own for the hand; the whole body's
    box would put one rectangle halfway between the two.
    """
    lo, hi = world.body_aabb(o.body)
    whole = [((lo[:2] + hi[:2]) / 2, world.yaw_of(o.body), np.array(o.model.extent[:2]) / 2, float(hi[2]))]
    lid = next(((pt, a) for pt, a in o.model.articulations.items() if a.kind == "lid"), None)
    if lid is None or not lid[1].is_open(world.joint_position(o, lid[0])):
        return whole
    link = o.links[lid[1].link]
    plate = next(lk for lk in o.model.links if lk.name == lid[1].link).shapes[0]
    blo, bhi = world.aabb(o.body, -1)
    _, lhi = world.aabb(o.body, link)
    return [
        ((blo[:2] + bhi[:2]) / 2, world.yaw_of(o.body), np.array(o.model.extent[:2]) / 2, float(bhi[2])),
        (
            world.to_world(o.body, link, plate.xyz)[:2],
            world.yaw_of(o.body, link),
            np.array(plate.size[:2]) / 2,
            float(lhi[2]),
        ),
    ]


def grasp_candidates(world: World, obj: SimObject) -> list[tuple[np.ndarray, tuple, float]]:
    """``(grasp point, hand orientation, width between the fingers)`` to try, best first.

    The model's sites (rims, both yaws of solids; nearest the robot first); for a small square solid
    beside taller neighbours (GSR-Bench cubes beside boxes) also a top-down grasp closing along the
    neighbour's wall and grasps leaning towards the wall (the palm away from it), closing along the
    wall or across the cube's faces.
    """
    sites = [s for g in obj.model.grasps for s in _rim_sites(g, obj)]
    sites.sort(key=lambda s: float(site_pose(world, obj, s)[0][0]))
    out = []
    for site in sites:
        pos, yaw = site_pose(world, obj, site)
        out.append((pos, top_down(yaw), site.width))
    sx, sy = obj.model.extent[:2]
    square = abs(sx - sy) < 1e-6 and math.hypot(sx, sy) < 0.06
    # a small package (LIBERO's cream cheese, butter) between tall neighbours gets the same treatment
    small = (
        obj.model.name != "mug"
        and all(math.hypot(*g.xyz[:2]) < 1e-6 for g in obj.model.grasps)
        and min(sx, sy) <= 0.06
        and max(sx, sy) <= MAX_CLOSING
    )
    if sites and (square or small):
        pos, face = site_pose(world, obj, sites[0])

        body_yaw = world.yaw_of(obj.body)

        def width(closing: float) -> float:  # the object's extent along a world closing direction
            t = closing - body_yaw
            return abs(math.cos(t)) * sx + abs(math.sin(t)) * sy

        extra = []
        for to_wall in walls_near(world, obj, float(pos[2]) + 0.03):
            along = to_wall + math.pi / 2
            nearest_face = face + round((to_wall - face) / (math.pi / 2)) * math.pi / 2
            extra += [
                (pos, top_down(along), width(along)),
                (pos, angled(to_wall, TILT, fingers_vertical=False), width(along)),
                (pos, angled(nearest_face, TILT, fingers_vertical=False), width(nearest_face + math.pi / 2)),
            ]
        out = out[:2] + [e for e in extra if e[2] <= MAX_CLOSING] + out[2:]
    return out


#: Grasps tried per pick (base spot planned and the arm checked for each), and grasps closed at most:
#: a grasp that misses or slips opens the hand, backs out along the approach and re-grasps.
MAX_CANDIDATES = 14
MAX_CLOSES = 3


def pick_candidates(world: World, obj: SimObject) -> list[tuple[np.ndarray, tuple, float]]:
    """``(grasp point, hand orientation, finger opening)`` for a pick, best first.

    The model's candidates (:func:`grasp_candidates`) and, for objects held whole (cubes, packages,
    small mugs), top-down grasps whose hand and open fingers clear walls and neighbours
    (:func:`gsr.skills.hand_clearance.clear_grasps`). Inside a container (a deep box) the cleared ones
    come first: there the model's poses put the hand into the walls.
    """
    model = [(pos, quat, min(GRIPPER.open_width, w + 0.035)) for pos, quat, w in grasp_candidates(world, obj)]
    whole = [g for g in obj.model.grasps if math.hypot(*g.xyz[:2]) < 1e-6]
    sx, sy = obj.model.extent[:2]
    if not whole or (obj.model.name != "mug" and min(sx, sy) > MAX_CLOSING):
        return model[:12]
    site, _ = site_pose(world, obj, whole[0])
    cleared = [(g.pos, g.quat, g.opening) for g in clear_grasps(world, obj, site, whole[0].width)]
    # a small mug's rim pinched (one finger inside it) after the whole-body grasps: it needs a finger's
    # room on one side only
    cleared += [(g.pos, g.quat, g.opening) for g in rim_pinches(world, obj)]
    if (support_of(world, obj.id) or ("", ""))[0] == "in":
        return (cleared + model)[:MAX_CANDIDATES]
    # beside tall neighbours the model's grasps keep their order (the leaning ones hold a package the
    # way a basket's walls let it go in again); those whose hand or fingers the proxy finds in
    # something come after the cleared ones (each costs a base search with IK before it is refused)
    ok = [hand_clear(world, obj, pos, quat, opening) for pos, quat, opening in model]
    first = [c for c, fits in zip(model[:10], ok[:10], strict=True) if fits]
    later = [c for c, fits in zip(model[:10], ok[:10], strict=True) if not fits] + model[10:]
    if not first:
        return (cleared + later)[:MAX_CANDIDATES]
    return (model[:10] + cleared + model[10:])[:MAX_CANDIDATES]


def pick(world: World, m: Motion, obj: SimObject) -> None:
    """Grasp ``obj`` by friction and lift it to transit height; raises SkillError on failure.

    Candidates are tried in order; the base is planned and the arm checked before anything moves, so a
    blocked candidate costs no motion. A grasp that closes on nothing or does not come up with the hand
    is retried from the object's new pose (at most :data:`MAX_CLOSES` closes).
    """
    if not obj.model.grasps or obj.model.fixed:
        raise SkillError(Failure.UNSUPPORTED, f"{obj.id} has no grasp site (a fixture)")
    z_transit = transit_height(world)
    lift(m, z_transit)
    errors: list[SkillError] = []
    closes = 0
    dragged = False
    while closes < MAX_CLOSES:
        tried = _approach(world, m, obj, z_transit, errors)
        if tried is None and not dragged:
            # a small solid by a deep box's end wall: drag it towards the middle with the fingertips;
            # only when no movable neighbour was in the candidates' way (the executor sets those aside
            # first: a drag beside one left a cube in a drawer where every close slipped, SAS Complex 13)
            dragged = True
            if not in_the_way(world, obj, [e.message for e in errors]) and _drag_inward(
                world, m, obj, z_transit, errors
            ):
                tried = _approach(world, m, obj, z_transit, errors)
        if tried is None:
            break
        pos, quat = tried
        closes += 1
        try:
            _close_and_lift(world, m, obj, pos, quat, z_transit)
            return
        except SkillError as exc:
            if exc.failure not in (Failure.GRASP_MISSED, Failure.GRASP_SLIPPED) or closes >= MAX_CLOSES:
                raise
            errors.append(exc)
            # let go, back out along the approach, and look again
            _unweld(world, obj)
            m.held = None
            m.gripper(GRIPPER.open_width, steps=GRIPPER.release_steps)
            m.ignore = {obj.body}
            m.move_line((np.array([m.pose()[0][0], m.pose()[0][1], z_transit]), m.pose()[1]), check=False)
            m.step(60)
    worst = max(errors, key=lambda e: list(Failure).index(e.failure)) if errors else None
    named = in_the_way(world, obj, [e.message for e in errors])
    raise SkillError(
        worst.failure if worst else Failure.UNREACHABLE,
        f"cannot reach a grasp on {obj.id}: "
        + "; ".join(_distinct(e.message for e in errors)[:3])
        + (f" (in the way: {', '.join(named)})" if named else ""),
    )


#: How a collision names its obstacle: ``collides with blue_mug1 (base) at the left finger``.
_OBSTACLE = re.compile(r"collides with ([^\s()]+) \(")


def in_the_way(world: World, obj: SimObject, messages: list[str]) -> list[str]:
    """The movable objects the refused candidates of a pick of ``obj`` ran into, most often named first:
    not fixtures, not what ``obj`` stands in or on (its box), not ``obj`` itself."""
    hosts: set[str] = set()
    node = obj.id
    while node in world.objects and len(hosts) < 8:
        support = support_of(world, node) or ("", "")
        node = support[1].split("/")[0]
        hosts.add(node)
    counts: dict[str, int] = {}
    for msg in messages:
        for name in _OBSTACLE.findall(msg):
            o = world.objects.get(name)
            if o is None or o.model.fixed or name == obj.id or name in hosts:
                continue
            counts[name] = counts.get(name, 0) + 1
    return sorted(counts, key=lambda n: -counts[n])


def _distinct(messages) -> list[str]:
    out: list[str] = []
    for msg in messages:
        if msg not in out:
            out.append(msg)
    return out


def _approach(
    world: World, m: Motion, obj: SimObject, z_transit: float, errors: list[SkillError]
) -> tuple[np.ndarray, tuple] | None:
    """Bring the open hand to the first candidate that can be reached without collision; its pose, or
    None when none can (the reasons are appended to ``errors``)."""
    centre = world.body_aabb(obj.body)[0] * 0.5 + world.body_aabb(obj.body)[1] * 0.5
    m.ignore = {obj.body}
    for pos, quat, opening in pick_candidates(world, obj):
        above = (np.array([pos[0], pos[1], z_transit]), quat)
        try:
            # plan the base and check the grasp pose before anything moves: blocked grasps cost no motion
            poses = [(pos, quat), (pos + np.array([0, 0, APPROACH]), quat), above]
            # (the straight path down is checked too, and followed as checked: Motion.descend_planned)
            base, _grasp_q = m.plan_base(centre, poses, clear=True, path=True)
            m.move_base(float(base[0]), float(base[1]))
            m.gripper(opening)
            down = [above, (pos + np.array([0, 0, APPROACH]), quat), (pos, quat)]
            m.move_continuous(above, down)
            m.descend_planned(down)
            return pos, quat
        except SkillError as exc:
            if exc.failure is Failure.TIMEOUT:
                raise
            errors.append(exc)
            lift(m, z_transit)
    return None


def _drag_inward(world: World, m: Motion, obj: SimObject, z_transit: float, errors: list[SkillError]) -> bool:
    """Drag ``obj`` along its container's floor towards the middle (see
    :func:`gsr.skills.hand_clearance.plan_drag`); whether it moved. Walls and neighbours are checked on
    the way; the object itself is what the fingertips press on."""
    on_the_way: list[str] = []
    drags = plan_drag(world, obj, on_the_way)
    # what stands on the way towards the middle is named when no drag got the object where a grasp
    # fits (the executor's recovery may set it aside and pick again)
    errors += [
        SkillError(Failure.BLOCKED, f"dragging {obj.id} inwards: its way collides with {name} (base)")
        for name in on_the_way
    ]
    if not drags:
        return False
    before = world.body_aabb(obj.body)[0].copy()
    m.ignore = {obj.body}
    m.gripper(0.0, steps=120)  # closed fingers: the base search checks the arm as it will be
    for drag in drags:
        quat, start, end = drag.quat, drag.start, drag.start + drag.shift
        hover = start + np.array([0, 0, 0.03])
        above = (np.array([start[0], start[1], z_transit]), quat)
        try:
            base, _ = m.plan_base(start, [(start, quat), (end, quat), (hover, quat), above], clear=True)
        except SkillError as exc:
            errors.append(SkillError(exc.failure, f"dragging {obj.id} inwards: {exc.message}"))
            continue
        try:
            m.move_base(float(base[0]), float(base[1]))
            m.move_continuous(above, [above, (hover, quat), (start, quat), (end, quat)])
            m.move_line((hover, quat))
            m.move_line((start, quat))
            m.step(20)
            m.move_line((end, quat))
            m.step(20)
            m.move_line((end + np.array([0, 0, 0.05]), quat), check=False)
            lift(m, z_transit)
        except SkillError as exc:
            if exc.failure is Failure.TIMEOUT:
                raise
            errors.append(SkillError(exc.failure, f"dragging {obj.id} inwards: {exc.message}"))
            lift(m, z_transit)
            return False
        break
    else:
        return False
    m.step(30)
    moved = float(np.linalg.norm(world.body_aabb(obj.body)[0][:2] - before[:2]))
    return moved > 0.01


def _close_and_lift(
    world: World, m: Motion, obj: SimObject, pos: np.ndarray, quat: tuple, z_transit: float
) -> None:
    z0 = world.body_aabb(obj.body)[0][2]
    if not m.grasp_close():
        raise SkillError(Failure.GRASP_MISSED, f"fingers closed on nothing at {obj.id}")
    if world.debug_weld:
        _weld(world, obj)
    m.step(20)
    m.held = obj.body
    m.move_line((np.array([pos[0], pos[1], z_transit]), quat), check=False)
    m.step(30)
    if world.body_aabb(obj.body)[0][2] < z0 + 0.03 or support_of(world, obj.id) != ("held", ""):
        raise SkillError(Failure.GRASP_SLIPPED, f"{obj.id} did not come up with the hand")


def _weld(world: World, obj: SimObject) -> None:
    """Debug option only: fix the object to the hand where it is (hides slips; never used by benchmarks)."""
    import pybullet as p

    r = world.robot
    ee_p, ee_q = r.ee_pose()
    # the joint frame: the object's centre of mass, expressed in the hand's frame and in its own
    ob_p, ob_q = p.getBasePositionAndOrientation(obj.body, physicsClientId=world.client)
    inv_p, inv_q = p.invertTransform(list(ee_p), list(ee_q))
    rel_p, rel_q = p.multiplyTransforms(inv_p, inv_q, ob_p, ob_q)
    world.welds[obj.id] = p.createConstraint(
        r.body,
        r.ee,
        obj.body,
        -1,
        p.JOINT_FIXED,
        (0, 0, 0),
        rel_p,
        (0, 0, 0),
        rel_q,
        (0, 0, 0, 1),
        physicsClientId=world.client,
    )


def _unweld(world: World, obj: SimObject) -> None:
    import pybullet as p

    cid = world.welds.pop(obj.id, None)
    if cid is not None:
        p.removeConstraint(cid, physicsClientId=world.client)


def target_point(
    world: World,
    target: str,
    obj: SimObject,
    relation: str,
    turn: float = 0.0,
    reachable: Callable[[np.ndarray, float], bool] | None = None,
    keep_clear: Rects = (),
) -> np.ndarray:
    """Where the held object's bottom centre should go: a free spot in the interior or on top of ``target``.

    On the bare table ``reachable(spot, turn)`` (the arm reaches the release there) is asked too, and
    the ``keep_clear`` rectangles ((centre, half sizes) on the table) count as occupied."""
    if relation == "in":
        for node_id, lo, hi, _ in interior_boxes(world):
            if node_id == target:
                lo, hi = _exposed(world, target, lo.copy(), hi.copy())
                # the open fingers reach past the object: keep them off the walls
                return _free_spot(world, obj, lo, hi, lo[2], inside=True)
        raise SkillError(Failure.UNSUPPORTED, f"{target} has no interior to put things in")
    if target in world.regions:
        r = world.regions[target]
        z = world.layout.table_height
        lo, hi = np.array([r.bounds[0], r.bounds[1], z]), np.array([r.bounds[2], r.bounds[3], z])
        return _free_spot(world, obj, lo, hi, z)
    loc = world.locate(target)
    if loc.body == world.table_body:
        # the bare table: a free spot near where the hand is, inside the table and outside named regions
        # (an object put "on the table" must not land "on" a region by accident)
        tlo, thi = world.body_aabb(world.table_body)
        ee = world.robot.ee_pose()[0]
        # near the hand first; the whole table when nothing near it is free (beside a cabinet whose
        # drawer is open over the table)
        # (a 25 cm box on a crowded desk: at last up to 1 cm from the desk's edges); in each, a spot where
        # the whole hand clears everything and the arm reaches first (beside a cabinet the first free
        # spot may put the 22 cm hand against the carcass); the first free spot only when none is
        accept = (lambda c: reachable(c, turn)) if reachable is not None else None
        fallback = None
        for reach, edge in ((0.25, 0.05), (2.0, 0.05), (2.0, 0.01)):
            lo = np.array([max(tlo[0] + edge, ee[0] - reach), max(tlo[1] + edge, ee[1] - reach), thi[2]])
            hi = np.array([min(thi[0] - edge, ee[0] + reach), min(thi[1] - edge, ee[1] + reach), thi[2]])
            spot, good = _ranked_spot(
                world,
                obj,
                lo,
                hi,
                float(thi[2]),
                avoid_regions=True,
                turn=turn,
                accept=accept,
                keep_clear=keep_clear,
            )
            if spot[2] <= thi[2] + 1e-6:
                if good:
                    return spot
                if fallback is None:
                    fallback = spot
        return fallback if fallback is not None else spot
    lo, hi = world.aabb(loc.body, loc.link) if loc.part else world.body_aabb(loc.body)
    if world.objects[loc.object_id].model.fixed:
        # a fixture's top (stove, rack, cabinet top): a level spot that supports the whole footprint,
        # at the height the surface really has there (not the top of a knob or a rail)

        spot = surface_spot(world, obj, loc.body, lo, hi, links={loc.link} if loc.part else None)
        if spot is not None:
            return spot
        return _free_spot(world, obj, lo, hi, hi[2], prefer_near=True)
    # on a movable thing (a bowl, a plate, a box): its middle, where it holds the object best
    return _free_spot(world, obj, lo, hi, hi[2])


#: Held objects wider than this (m) are turned square to the table when no spot fits them as they are.
WIDE = 0.15


def riders_of(world: World, obj: SimObject) -> set[int]:
    """Bodies resting in or on ``obj`` (a box's contents), directly or on each other."""
    found: set[int] = set()
    hosts = {obj.id}
    while True:
        more = [
            o
            for o in world.objects.values()
            if o.body not in found and o.id not in hosts and (support_of(world, o.id) or ("", ""))[1] in hosts
        ]
        if not more:
            return found
        found |= {o.body for o in more}
        hosts |= {o.id for o in more}


def _spot_and_turn(
    world: World,
    target: str,
    obj: SimObject,
    relation: str,
    reachable: Callable[[np.ndarray, float], bool] | None = None,
    keep_clear: Rects = (),
) -> tuple[np.ndarray, float]:
    """The release spot and a wrist turn (rad): a wide object (a 25 cm box taken off another box) that
    fits nowhere on a crowded table as held, turned by 45 degrees say, may fit turned square to it."""
    spot = target_point(world, target, obj, relation, reachable=reachable, keep_clear=keep_clear)
    loc = world.locate(target) if target not in world.regions else None
    if loc is None or loc.body != world.table_body or max(obj.model.extent[:2]) < WIDE:
        return spot, 0.0
    if spot[2] <= world.body_aabb(world.table_body)[1][2] + 1e-6:
        return spot, 0.0
    yaw = world.yaw_of(obj.body)
    square = -(((yaw + math.pi / 4) % (math.pi / 2)) - math.pi / 4)  # the smallest turn to the axes
    for turn in (square, square + math.pi / 2, square - math.pi / 2):
        if abs(turn) > math.pi * 0.6:
            continue
        turned = target_point(
            world, target, obj, relation, turn=turn, reachable=reachable, keep_clear=keep_clear
        )
        if turned[2] <= world.body_aabb(world.table_body)[1][2] + 1e-6:
            return turned, turn
    return spot, 0.0


def _exposed(world: World, target: str, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The part of a drawer's interior that is out of its cabinet (the rest is under the carcass)."""
    if target not in world.parts:
        return lo, hi
    obj_id, part = world.parts[target]
    obj = world.objects[obj_id]
    art = obj.model.articulations.get(part)
    if art is None or art.kind != "drawer":
        return lo, hi
    axis = world.joint_axis(obj, part)
    clo, chi = world.aabb(obj.body, -1)
    k = int(np.argmax(np.abs(axis[:2])))
    # 3 cm off the carcass: the hand above the object must clear the cabinet's front edge
    if axis[k] < 0:
        hi[k] = min(hi[k], clo[k] - 0.03)
    else:
        lo[k] = max(lo[k], chi[k] + 0.03)
    if lo[k] >= hi[k]:
        raise SkillError(Failure.BLOCKED, f"{target} is not open far enough to put anything in")
    return lo, hi


#: The widest step (m) between the spots a free-spot search tries.
SPOT_STEP = 0.03

#: Room kept between an object set on the bare table and a fixture's parts (m): the hand's half width.
FIXTURE_HAND_ROOM = 0.05


#: Table spots a release-spot search asks ``accept`` (the arm's reach) about at most, and how far (m)
#: a spot must be from one refused before it is asked about.
ACCEPT_TRIES = 6
ACCEPT_SPACING = 0.05


def _free_spot(
    world: World,
    obj: SimObject,
    lo: np.ndarray,
    hi: np.ndarray,
    z: float,
    prefer_near: bool = False,
    inside: bool = False,
    avoid_regions: bool = False,
    turn: float = 0.0,
) -> np.ndarray:
    """A point in the rectangle lo..hi where the held object fits, with room for the fingers.

    Along the fingers' closing axis the open fingers need about 2 cm beside the object (walls and
    neighbours), across it half a centimetre. Free floor spots first; when the floor is full (cubes
    packed in a box), the spot whose objects underneath are lowest, at their top: a second layer.
    """
    return _ranked_spot(world, obj, lo, hi, z, prefer_near, inside, avoid_regions, turn)[0]


def _ranked_spot(
    world: World,
    obj: SimObject,
    lo: np.ndarray,
    hi: np.ndarray,
    z: float,
    prefer_near: bool = False,
    inside: bool = False,
    avoid_regions: bool = False,
    turn: float = 0.0,
    accept: Callable[[np.ndarray], bool] | None = None,
    keep_clear: Rects = (),
) -> tuple[np.ndarray, bool]:
    """``_free_spot``'s point and whether it is a good one: free with the whole hand clear of
    everything (inside a container: free) and, with ``accept``, taken by it. When no free spot is
    good, the point is the first hand-clear free one, else the first free one, else a second layer."""
    ee_q = world.robot.ee_pose()[1]
    import pybullet as p

    rot = np.array(p.getMatrixFromQuaternion(list(ee_q))).reshape(3, 3)
    e1 = rot[:2, 1] / max(np.linalg.norm(rot[:2, 1]), 1e-9)  # the closing axis (hand y) on the table
    olo, ohi = world.body_aabb(obj.body)
    oh = (ohi[:2] - olo[:2]) / 2
    if turn:  # the wrist will turn by ``turn`` before the object goes down: its footprint turns with it
        c, s_ = math.cos(turn), math.sin(turn)
        e1 = np.array([c * e1[0] - s_ * e1[1], s_ * e1[0] + c * e1[1]])
        yaw = world.yaw_of(obj.body) + turn
        sx, sy = obj.model.extent[:2]
        oh = (
            np.array(
                [
                    abs(math.cos(yaw)) * sx + abs(math.sin(yaw)) * sy,
                    abs(math.sin(yaw)) * sx + abs(math.cos(yaw)) * sy,
                ]
            )
            / 2
        )
    e2 = np.array([-e1[1], e1[0]])

    def reach(e: np.ndarray, h: np.ndarray) -> float:  # half-width of an AABB footprint along e
        return float(abs(e[0]) * h[0] + abs(e[1]) * h[1])

    gap1, gap2 = (0.02, 0.006) if inside else (0.005, 0.005)
    # shrink the area: the object's footprint plus the fingers' room, per world axis
    mx = reach(np.array([1.0, 0.0]), oh) + abs(e1[0]) * gap1 + abs(e2[0]) * gap2
    my = reach(np.array([0.0, 1.0]), oh) + abs(e1[1]) * gap1 + abs(e2[1]) * gap2
    xlo, xhi, ylo, yhi = lo[0] + mx, hi[0] - mx, lo[1] + my, hi[1] - my
    if xlo > xhi:
        xlo = xhi = (lo[0] + hi[0]) / 2
    if ylo > yhi:
        ylo = yhi = (lo[1] + hi[1]) / 2
    others = []
    for o in world.objects.values():
        if o.id == obj.id:
            continue
        if o.model.fixed:
            if avoid_regions:
                # the bare table: a fixture's parts (an open drawer over the table, the carcass) are
                # obstacles too, with room for the hand beside them
                for link in range(-1, p.getNumJoints(o.body, physicsClientId=world.client)):
                    alo, ahi = world.aabb(o.body, link)
                    if ahi[2] > z + 0.005:
                        half = (ahi[:2] - alo[:2]) / 2 + FIXTURE_HAND_ROOM
                        others.append(((alo[:2] + ahi[:2]) / 2, half, float(ahi[2])))
            continue
        alo, ahi = world.body_aabb(o.body)
        if ahi[2] > z - 0.005 and alo[2] < z + 0.15 and support_of(world, o.id) != ("held", ""):
            others.append(((alo[:2] + ahi[:2]) / 2, (ahi[:2] - alo[:2]) / 2, float(ahi[2])))
    # rectangles the caller keeps free (the hand's room round an object a pick must reach next); with
    # no free spot anywhere, the fallback may still use them at the table's height (never on top of them)
    others += [(np.asarray(c, dtype=float), np.asarray(h, dtype=float), z) for c, h in keep_clear]
    # 7 x 7 spots at least, 3 cm apart at most (a 25 cm box needs a gap a coarse grid steps over)
    nx = int(min(41, max(7, math.ceil((xhi - xlo) / SPOT_STEP) + 1)))
    ny = int(min(41, max(7, math.ceil((yhi - ylo) / SPOT_STEP) + 1)))
    candidates = [np.array([x, y]) for x in np.linspace(xlo, xhi, nx) for y in np.linspace(ylo, yhi, ny)]
    centre = np.array([(xlo + xhi) / 2, (ylo + yhi) / 2])
    if prefer_near:  # a fixture top: the edge nearest the robot is the easiest to reach
        # ... where the hand does not meet a tall neighbour (a bowl beside a wine bottle)

        crowded = hand_crowding(world, obj, z)
        candidates.sort(key=lambda c: (crowded(c), c[0] + 0.3 * abs(c[1] - centre[1])))
    else:
        candidates.sort(key=lambda c: float(np.linalg.norm(c - centre)))

    def under(c: np.ndarray) -> list[float]:
        tops = []
        for oc, ohalf, top in others:
            d = c - oc
            apart1 = abs(d @ e1) >= reach(e1, oh) + reach(e1, ohalf) + gap1
            apart2 = abs(d @ e2) >= reach(e2, oh) + reach(e2, ohalf) + gap2
            if not (apart1 or apart2):
                tops.append(top)
        return tops

    def in_region(c: np.ndarray) -> bool:
        return avoid_regions and any(
            r.bounds[0] - oh[0] < c[0] < r.bounds[2] + oh[0]
            and r.bounds[1] - oh[1] < c[1] < r.bounds[3] + oh[1]
            for r in world.regions.values()
        )

    free = [c for c in candidates if not under(c) and not in_region(c)]
    if not free:
        best = min(candidates, key=lambda c: max(under(c)))
        return np.array([best[0], best[1], max(z, max(under(best)) + 0.003)]), False
    if avoid_regions:
        # the bare table: spots with a hand's width (10 cm) around them first, so the object set down
        # does not stand in the way of the next grasps and handles (stable: nearest first within a tie)
        def clearance(c: np.ndarray) -> float:
            gaps = [
                max(abs(c[0] - oc[0]) - ohalf[0] - oh[0], abs(c[1] - oc[1]) - ohalf[1] - oh[1])
                for oc, ohalf, _top in others
            ]
            return min([0.1, *gaps])

        free.sort(key=lambda c: -round(clearance(c), 9))
    if inside:
        return np.array([free[0][0], free[0][1], z]), True
    # the hand reaches past what it holds (it is 20 cm long; a box is held by its wall): the first free
    # spot where the hand at the release point and above it touches nothing, and that ``accept`` (the
    # arm reaches it) takes; else the first hand-clear one; else the first free one

    cleared = None
    refused: list[np.ndarray] = []
    for c in free:
        if not hand_clear_at(world, obj, np.array([c[0], c[1], z]), turn):
            continue
        if cleared is None:
            cleared = c
        if accept is None:
            return np.array([c[0], c[1], z]), True
        if len(refused) >= ACCEPT_TRIES:
            break
        if any(float(np.linalg.norm(c - r)) < ACCEPT_SPACING for r in refused):
            continue  # a neighbour of a refused spot: most likely refused too
        if accept(np.array([c[0], c[1], z])):
            return np.array([c[0], c[1], z]), True
        refused.append(c)
    pick = cleared if cleared is not None else free[0]
    return np.array([pick[0], pick[1], z]), False


#: Offsets (m) from a box's middle along its long side and across it where a spot a later pick reaches
#: is looked for, nearest the middle first (in an 8.5 cm deep box a grasp fits within about 3 cm of it).
LATER_ALONG = (0.0, 0.015, -0.015, 0.03, -0.03)
LATER_ACROSS = (0.0, 0.02, -0.02)


def graspable_later(
    world: World, obj: SimObject, target: str, packed: tuple[np.ndarray, float]
) -> tuple[np.ndarray, float]:
    """The packing's ``(spot, wrist turn)`` in a box (a whole object's interior, not a drawer's or a
    compartment's), or, when a later pick would find no grasp of ``obj`` there
    (:func:`gsr.skills.hand_clearance.graspable_at`: a cube let go against a deep box's wall or in its
    corner), the free spot nearest the box's middle where one would; the packing's when there is none."""
    spot, delta = packed
    found = world.interior_of(target) if target in world.objects else None
    if found is None:
        return packed
    yaw = world.yaw_of(obj.body) + delta
    if graspable_at(world, obj, spot, yaw):
        return packed
    host, _, interior = found
    link = host.links[interior.link]
    centre = world.to_world(host.body, link, interior.center)
    half = np.array(interior.size[:2]) / 2
    box_yaw = world.yaw_of(host.body, link) + (math.pi / 2 if half[1] > half[0] else 0.0)
    axis = np.array([math.cos(box_yaw), math.sin(box_yaw)])
    across = np.array([-axis[1], axis[0]])
    lo, hi = world.body_aabb(obj.body)
    reach = float(max(hi[:2] - lo[:2])) / 2 + 0.004  # the object's footprint (turned: its widest) and 4 mm
    # what already lies in the box: a spot must keep its footprint off theirs
    inside = [
        world.body_aabb(o.body)
        for o in world.objects.values()
        if o.id != obj.id and (support_of(world, o.id) or ("", ""))[1] == target
    ]
    for a in LATER_ALONG:
        for b in LATER_ACROSS:
            xy = centre[:2] + a * axis + b * across
            if any(
                np.all(np.abs(xy - (olo[:2] + ohi[:2]) / 2) < reach + (ohi[:2] - olo[:2]) / 2)
                for olo, ohi in inside
            ):
                continue  # something already stands there
            here = np.array([xy[0], xy[1], spot[2]])
            if graspable_at(world, obj, here, yaw):
                return here, delta
    return packed


#: Where a release in a container stopped high, other spots are tried this far apart (m), at most
#: :data:`CLEAR_SPOT_TRIES` of them, nearest the packing's spot first.
CLEAR_SPOT_STEP = 0.02
CLEAR_SPOT_TRIES = 40
#: Heights (m) above the release point at which the hand may stop and still let go (below
#: :data:`MAX_DROP`, with the descent's 1 cm steps and 3 mm contact margin to spare), lowest first: over
#: a cube on an 8.5 cm deep box's floor the 20 cm hand fits only lying inside the box, which an object
#: in the box's middle (a mug) rules out everywhere; 3-4.5 cm higher the hand is above the walls and
#: only the fingers must be inside them.
RELEASE_LIFTS = (0.0, 0.015, 0.03, 0.045)


def hand_clear_spot(
    world: World, obj: SimObject, target: str, spot: np.ndarray, turn: float = 0.0
) -> np.ndarray | None:
    """:func:`hand_clear_release` with the wrist turned by ``turn`` only: the spot, or None."""
    found = hand_clear_release(world, obj, target, spot, turns=(turn,))
    return None if found is None else found[0]


#: Room (rad) kept from the wrist's last joint's limits when a release turns the held object.
WRIST_ROOM = 0.15


def wrist_turns(world: World, target: str | None = None) -> tuple[float, ...]:
    """Turns of the hand (pointing down) about the vertical for a release: none first, then those that
    lay its closing axis along the container ``target``'s walls (across them, then along), then the
    quarter turns; each as the wrist's last joint can make it (it turns the other way round: a yaw of
    +d is a joint move of -d; of d and d +- pi, the same grasp, the one nearest the joint's middle)."""
    import pybullet as p

    robot = world.robot
    q7 = float(robot.q()[8])
    mid = (robot.lower[8] + robot.upper[8]) / 2

    def can(d: float) -> bool:
        return robot.lower[8] + WRIST_ROOM <= q7 - d <= robot.upper[8] - WRIST_ROOM

    rot = np.array(p.getMatrixFromQuaternion(list(robot.ee_pose()[1]))).reshape(3, 3)
    closing = math.atan2(rot[1, 1], rot[0, 1])
    wanted: list[float] = []
    found = world.interior_of(target) if target is not None and target in world.objects else None
    if found is not None:
        host, _, interior = found
        yaw = world.yaw_of(host.body, host.links[interior.link])
        sx, sy = interior.size[:2]
        short, long_ = (yaw, yaw + math.pi / 2) if sx <= sy else (yaw + math.pi / 2, yaw)
        wanted += [(a - closing + math.pi / 2) % math.pi - math.pi / 2 for a in (short, long_)]
    wanted += [math.pi / 2, -math.pi / 2]
    out = [0.0]
    for d in wanted:
        ways = sorted((x for x in (d, d + math.pi, d - math.pi) if can(x)), key=lambda x: abs(q7 - x - mid))
        if ways and all(abs(ways[0] - o) > 0.05 for o in out):
            out.append(ways[0])
    return tuple(out)


def hand_clear_release(
    world: World,
    obj: SimObject,
    target: str,
    spot: np.ndarray,
    turns: tuple[float, ...] = (0.0,),
) -> tuple[np.ndarray, float] | None:
    """``(spot, turn)``: a spot in the container ``target`` (a box or a drawer) for the held ``obj``,
    nearest ``spot``, whose footprint stays inside the interior and off what already lies there, and
    where the hand holding ``obj`` as it does now with the wrist turned by one of ``turns`` (first
    first), at the release point or at most the highest of :data:`RELEASE_LIFTS` above it and straight
    above that, touches nothing (:func:`gsr.skills.hand_clearance.hand_clear_at`); the lowest such
    height wins over the turn's order and nearness. None when there is none. For a release whose descent stopped high (the hand met the drawer above, a
    wall top or a neighbour before the object got down): ``place`` descends until contact and lets go
    there, up to :data:`MAX_DROP` above the release point."""
    found = world.interior_of(target)
    if found is None:
        return None
    host, _, interior = found
    link = host.links[interior.link]
    centre = world.to_world(host.body, link, interior.center)
    half = np.array(interior.size[:2]) / 2
    yaw = world.yaw_of(host.body, link)
    axes = np.array([[math.cos(yaw), math.sin(yaw)], [-math.sin(yaw), math.cos(yaw)]])
    lo, hi = world.body_aabb(obj.body)
    reach = float(max(hi[:2] - lo[:2])) / 2 + 0.004
    inside = [
        world.body_aabb(o.body)
        for o in world.objects.values()
        if o.id != obj.id and (support_of(world, o.id) or ("", ""))[1] == target
    ]
    room = half - reach
    if np.any(room < 0):
        return None
    grid = [
        centre[:2] + a * axes[0] + b * axes[1]
        for a in np.arange(-room[0], room[0] + 1e-9, CLEAR_SPOT_STEP)
        for b in np.arange(-room[1], room[1] + 1e-9, CLEAR_SPOT_STEP)
    ]
    grid.sort(key=lambda xy: float(np.linalg.norm(xy - spot[:2])))
    free = [
        np.array([xy[0], xy[1], spot[2]])
        for xy in grid
        if float(np.linalg.norm(xy - spot[:2])) >= CLEAR_SPOT_STEP / 2  # not the spot that stopped high
        and not any(
            np.all(np.abs(xy - (olo[:2] + ohi[:2]) / 2) < reach + (ohi[:2] - olo[:2]) / 2)
            for olo, ohi in inside
        )
    ][:CLEAR_SPOT_TRIES]
    for h in RELEASE_LIFTS:
        for turn in turns:
            for here in free:
                if hand_clear_at(world, obj, here, turn, lift=h, margin=RELEASE_MARGIN):
                    return here, turn
    return None


def _recentre(
    world: World, m: Motion, obj: SimObject, spot: np.ndarray, goal: np.ndarray, quat: tuple, z: float
) -> np.ndarray:
    """The hand goal corrected for where the held object really is now; the hand moves over it at ``z``."""
    m.step(10)
    lo, hi = world.body_aabb(obj.body)
    err = spot[:2] - (lo[:2] + hi[:2]) / 2
    if float(np.linalg.norm(err)) <= 0.003:
        return goal
    goal = goal + np.array([err[0], err[1], 0.0])
    m.move_line((np.array([goal[0], goal[1], z]), quat))
    return goal


def _release_reach(
    m: Motion, offset: np.ndarray, quat: tuple, z_transit: float
) -> Callable[[np.ndarray, float], bool]:
    """``reachable(spot, turn)``: whether some base spot lets the arm hold the object (grasped with
    ``offset`` / ``quat``, the wrist turned by ``turn``) at its release point over ``spot`` and straight
    above it at transit height, as ``place`` will move it; nothing moves."""
    import pybullet as p

    def reachable(spot: np.ndarray, turn: float) -> bool:
        q, off = quat, offset
        if turn:
            c, s = math.cos(turn), math.sin(turn)
            off = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
            q = tuple(
                p.multiplyTransforms((0, 0, 0), p.getQuaternionFromEuler((0, 0, turn)), (0, 0, 0), quat)[1]
            )
        goal = np.asarray(spot, dtype=float) + off + np.array([0, 0, 0.012])
        above = np.array([goal[0], goal[1], max(z_transit, goal[2] + APPROACH)])
        try:
            m.plan_base(goal, [(goal, q), (above, q)], clear=True)
        except SkillError:
            return False
        return True

    return reachable


def place(
    world: World, m: Motion, obj: SimObject, target: str, relation: str, keep_clear: Rects = ()
) -> None:
    """Put the held ``obj`` on or in ``target`` and release it; the caller checks the outcome.

    ``keep_clear``: rectangles ((centre, half sizes) on the table) a bare-table spot must stay out of."""
    import pybullet as p

    ee, quat = m.pose()
    lo, hi = world.body_aabb(obj.body)
    centre = (lo + hi) / 2
    # the grasp offset as it is now: where the hand must be for the object's bottom centre to be at spot
    offset = ee - np.array([centre[0], centre[1], lo[2]])
    rot = np.array(p.getMatrixFromQuaternion(list(quat))).reshape(3, 3)

    # a container with a roof (a microwave): set the object down before its opening, then slide it in
    opening = roofed_opening(world, target, obj) if relation == "in" else None
    packed = (
        packed_spot(world, obj, target, math.atan2(rot[1, 1], rot[0, 1]))
        if relation == "in" and opening is None
        else None
    )
    if packed is not None and relation == "in":
        packed = graspable_later(world, obj, target, packed)
    if opening is not None:
        spot, delta = opening[0], 0.0
    elif packed is not None:
        # containers: a spot in the container's frame, the wrist turned to line the object up with it
        spot, delta = packed
    else:
        spot, delta = _spot_and_turn(
            world,
            target,
            obj,
            relation,
            reachable=_release_reach(
                m, offset, quat, transit_height(world, extra=hi[2] - lo[2], exclude=(obj.id,))
            ),
            keep_clear=keep_clear,
        )
        if not delta:
            # the hand's 22 cm length turned away from a tall neighbour (a bottle beside the bowl)
            delta = uncrowded_turn(world, obj, spot)
    if delta:
        turn = p.getQuaternionFromEuler((0, 0, delta))
        quat = tuple(p.multiplyTransforms((0, 0, 0), turn, (0, 0, 0), quat)[1])
        c, s = math.cos(delta), math.sin(delta)
        offset = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
    goal = spot + offset + np.array([0, 0, 0.012])
    z_transit = max(transit_height(world, extra=hi[2] - lo[2], exclude=(obj.id,)), goal[2] + APPROACH)
    riders = riders_of(world, obj)
    m.ignore = {obj.body} | riders  # what rides in the held box moves with it
    m.gentle = bool(riders)  # (Motion.gentle: smooth targets, or the riders creep)
    lift(m, z_transit)
    m.park_for(goal, poses=[(goal, quat), (np.array([goal[0], goal[1], z_transit]), quat)])
    above = (np.array([goal[0], goal[1], z_transit]), quat)
    way_down = [above, (goal + np.array([0, 0, 0.04]), quat), (goal, quat)]
    try:
        m.move_continuous(above, way_down)
    except SkillError as exc:
        if exc.failure is not Failure.BLOCKED:
            raise
        # the arm, not the hand, met something on the way over (a shoulder against a tall cabinet by
        # the desk): a base spot from which the arm above the spot touches nothing, then again
        base, _ = m.plan_base(goal, [above, (goal, quat)], clear=True)
        lift(m, z_transit)
        m.move_base(float(base[0]), float(base[1]))
        m.move_continuous(above, way_down)
    # the object shifts in the fingers on the way (the two fingers are not coupled, and the wrist turned):
    # re-measure it above the spot, before descending past neighbours and walls, and again just above
    goal = _recentre(world, m, obj, spot, goal, quat, z_transit)
    # (a hand that leans, holding a package it took from between tall neighbours, may meet a wall top
    # of a deep basket before that: it stops there and the release below decides)
    m.move_until_contact((goal + np.array([0, 0, 0.04]), quat))
    goal = _recentre(world, m, obj, spot, goal, quat, float(m.pose()[0][2]))
    # down to the release point, or as low as the hand gets without touching a wall top or a neighbour
    # (the Panda's hand is 22 cm long: over a 3 cm cube in an 8.5 cm deep box it cannot reach the floor;
    # the object is then let go a few centimetres above it)
    short = m.move_until_contact((goal, quat))
    if short > MAX_DROP and packed is not None and opening is None:
        # the hand met something before the object got down (the drawer above, a neighbour): straight
        # back up, then once more over the nearest spot in the container where the hand clears all
        # (a turn of the wrist lays the 20 cm hand across the box: over a box whose middle is taken,
        # the free spots are by its end walls, where a hand lying along or aslant the box meets one)
        other = hand_clear_release(world, obj, target, spot, turns=wrist_turns(world, target))
        if other is not None:
            m.move_line((np.array([m.pose()[0][0], m.pose()[0][1], z_transit]), quat), check=False)
            spot, turn_more = other
            if turn_more:
                quat = tuple(
                    p.multiplyTransforms(
                        (0, 0, 0), p.getQuaternionFromEuler((0, 0, turn_more)), (0, 0, 0), quat
                    )[1]
                )
                c, s = math.cos(turn_more), math.sin(turn_more)
                offset = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
            goal = spot + offset + np.array([0, 0, 0.012])
            above = (np.array([goal[0], goal[1], z_transit]), quat)
            m.park_for(goal, poses=[(goal, quat), above])
            m.move_continuous(above, [above, (goal + np.array([0, 0, 0.04]), quat), (goal, quat)])
            goal = _recentre(world, m, obj, spot, goal, quat, z_transit)
            m.move_until_contact((goal + np.array([0, 0, 0.04]), quat))
            goal = _recentre(world, m, obj, spot, goal, quat, float(m.pose()[0][2]))
            short = m.move_until_contact((goal, quat))
    if short > MAX_DROP:
        raise SkillError(
            Failure.BLOCKED, f"the hand stops {short:.3f} m above the release point of {obj.id} in {target}"
        )
    m.step(10)
    # open just enough to let go: wide-open fingers would sweep into neighbours (packed boxes)
    _unweld(world, obj)
    m.gripper(min(GRIPPER.open_width, world.robot.finger_width() + 0.016), steps=60)
    m.held = None
    m.step(40)
    pos, quat = m.pose()
    m.move_line((np.array([pos[0], pos[1], pos[2] + APPROACH]), quat), check=False)
    m.ignore = set()
    m.step(60)
    if opening is not None:
        push_in(world, m, obj, opening[1], target)
