"""Skills on articulated parts and pushing: open/close drawers and lids, turn knobs, press buttons, push.

Drawers are pulled by their bar handle with the hand horizontal (fingers closing vertically round the
bar); sliding lids by their tab from above; knobs are grasped from above and turned with the wrist;
buttons are pressed with closed fingers. Every motion is a friction contact, checked afterwards against
the joint positions (and the button latch).
"""

from __future__ import annotations

import math

import numpy as np
from gsr.skills.arm_moves import APPROACH, lift, transit_height
from gsr.skills.asset_model import Articulation
from gsr.skills.motion import Motion
from gsr.skills.result import Failure, SkillError
from gsr.skills.robot import angled, approach_axis, top_down
from gsr.skills.sim_graph import support_of
from gsr.skills.world import SimObject, World


def _axis_world(world: World, obj: SimObject, art: Articulation) -> np.ndarray:
    """The joint axis of a prismatic part in world coordinates (unit, pointing towards 'open')."""
    part = next(k for k, v in obj.model.articulations.items() if v is art)
    return world.joint_axis(obj, part)


def _node_of(world: World, obj: SimObject, part: str) -> str:
    """The graph node id of an object's part (the object itself when no part node names it)."""
    return next((nid for nid, (oid, pt) in world.parts.items() if oid == obj.id and pt == part), obj.id)


def _handle(world: World, obj: SimObject, art: Articulation) -> tuple[np.ndarray, float]:
    assert art.handle is not None
    link = obj.links[art.handle.link]
    return world.to_world(obj.body, link, art.handle.xyz), world.yaw_of(obj.body, link) + art.handle.yaw


#: m the hand backs off out of a front part's way when it cannot rise to transit height first
BACK_OFF = 0.1


def _clear_of_part(world: World, m: Motion, obj: SimObject, art: Articulation, front: bool) -> None:
    """Raise the hand to transit height before the base moves; for a front handle, when the arm cannot
    raise it that high from where it is (the tilted hand left low at the drawer's front by a stroke that
    ended short, a finger still on the part), first back it off along its approach axis, the part's own
    link not counted as an obstacle while the hand leaves it.

    The base slides with the arm held still and only its own links checked: a hand left on the part's
    front would be carried into it by a base that comes forward for the next stroke, and the joint-space
    approach would start in contact with the part itself (``blocked`` by the drawer being closed).
    """
    z = transit_height(world)
    lift(m, z)
    pos, quat = m.pose()
    if not front or pos[2] >= z - 0.005:
        return
    m.ignore_links = {(obj.body, obj.links[art.link])}
    try:
        m.move_line((pos - approach_axis(quat) * BACK_OFF, quat))
    except SkillError as exc:
        if exc.failure not in (Failure.BLOCKED, Failure.IK_FLIP, Failure.UNREACHABLE):
            raise
        return
    finally:
        m.ignore_links = set()
    lift(m, z)


def _slide(world: World, m: Motion, obj: SimObject, part: str, art: Articulation, target: float) -> None:
    """Move a prismatic part along its axis to joint position ``target``.

    Opening grasps the handle and pulls; closing pushes the handle with closed fingers (grasping it
    could catch whatever now sits in the open drawer).
    """
    axis = _axis_world(world, obj, art)
    handle, yaw = _handle(world, obj, art)
    assert art.handle is not None
    front = art.handle.approach == "front"
    q0 = world.joint_position(obj, part)
    sign = 1 if art.open > art.closed else -1
    travel = axis * (target - q0) * sign
    pushing = float(np.dot(travel, axis)) < 0 and front
    # front handles are vertical bars: tilt the hand towards the part, fingers closing sideways
    quat = angled(math.atan2(-axis[1], -axis[0]), fingers_vertical=False) if front else top_down(yaw)
    back = -approach_axis(quat) * 0.1 if front else np.array([0, 0, APPROACH])
    contact = handle + axis * (0.02 if pushing else 0.0)  # pushing: the fingertips meet the bar's front
    _clear_of_part(world, m, obj, art, front)
    # the arm works best in the middle of the stroke; a tilted hand keeps its wrist 6 cm further back
    overshoot = axis * 0.01 * (-1 if pushing else 1)
    poses = [(contact + back, quat), (contact, quat), (contact + travel + overshoot, quat)]
    m.park_for(contact + travel / 2, standoff=0.58 if front else 0.5, poses=poses)
    if pushing:
        m.gripper(0.0, steps=30)
    else:
        m.gripper(art.handle.width + 0.04)
    m.ignore = set()
    # arrive on the arm configuration from which the approach and the stroke are one smooth motion
    start = m.continuous_start(poses, m.robot.q()[:2])
    if start is not None:
        m.move_joint(start)
    m.move_line((contact + back, quat))
    m.ignore_links = {(obj.body, obj.links[art.link])}
    m.move_line((contact, quat))
    m.ignore_links = set()
    if not pushing and not m.grasp_close():
        raise SkillError(Failure.GRASP_MISSED, f"missed the handle of {obj.id}:{part}")
    # what rides in the part moves with it: not an obstacle for the stroke
    riders = {
        o.body
        for o in world.objects.values()
        if (support_of(world, o.id) or ("", ""))[1] == _node_of(world, obj, part)
    }
    m.ignore = {obj.body} | riders
    m.move_line((contact + travel + overshoot, quat), check=True)
    m.step(30)
    if not pushing:
        m.release()
    pos, _ = m.pose()
    retreat = pos + (back * 0.4 + np.array([0, 0, 0.05]) if front else np.array([0, 0, APPROACH]))
    m.move_line((retreat, quat), check=False)
    m.ignore = set()


#: Door angles (rad) tried as the end of an opening stroke, widest first; all are past half travel.
#: rad the wrist turns past a knob's target: the knob ends against its stop, not a few degrees short
#: of it where the next grasp can spin it out of the fingers
KNOB_OVERSHOOT = 0.15
DOOR_STEP = 0.05  # rad between the arc's waypoints (1.7 cm at a 33 cm handle radius)


def _door_arc(
    world: World, obj: SimObject, part: str, art: Articulation, target: float
) -> list[tuple[np.ndarray, tuple[float, float, float, float]]]:
    """Hand poses on the handle from the door's angle now to ``target``: the handle's arc about the
    hinge, the tilted hand turning with the door so it keeps pointing into it."""
    link = obj.links[art.link]
    hinge = world.to_world(obj.body, link, (0.0, 0.0, 0.0))  # the joint frame's origin lies on the axis
    up = float(world.joint_axis(obj, part)[2]) * (1 if art.open > art.closed else -1)  # +1: about +z
    handle, _ = _handle(world, obj, art)
    q0 = world.joint_position(obj, part)
    yaw0 = world.yaw_of(obj.body, link)  # the door's outward normal is its link's -x: point along +x
    n = max(1, math.ceil(abs(target - q0) / DOOR_STEP))
    poses = []
    for i in range(n + 1):
        d = up * (target - q0) * i / n
        c, s_ = math.cos(d), math.sin(d)
        r = handle[:2] - hinge[:2]
        xy = hinge[:2] + np.array([c * r[0] - s_ * r[1], s_ * r[0] + c * r[1]])
        poses.append((np.array([xy[0], xy[1], handle[2]]), angled(yaw0 + d, fingers_vertical=False)))
    return poses


def _swing(world: World, m: Motion, obj: SimObject, part: str, art: Articulation, target: float) -> None:
    """Open or close a revolute door: grasp its vertical pull bar with the tilted hand, carry the bar
    along its arc about the hinge (the wrist turning with the door), let go and back off.

    Opening tries the widest end angle the arm can follow without an IK branch flip first; any end past
    half travel makes the door open.
    """
    assert art.handle is not None
    span = art.open - art.closed
    if target == art.open or (art.open - target) * (1 if span > 0 else -1) < 0:
        ends = [art.closed + span * f for f in (1.0, 0.85, 0.7)]
    else:
        ends = [target]
    lift(m, transit_height(world))
    errors = []
    for end in ends:
        arc = _door_arc(world, obj, part, art, end)
        quat = arc[0][1]
        back = -approach_axis(quat) * 0.1
        key = [(arc[0][0] + back, quat), *arc[:: max(1, len(arc) // 6)], arc[-1]]
        try:
            m.park_for((arc[0][0] + arc[-1][0]) / 2, standoff=0.58, poses=key)
            break
        except SkillError as exc:
            errors.append(f"to {end:.2f} rad: {exc.message}")
    else:
        raise SkillError(Failure.UNREACHABLE, f"no base position follows the door of {obj.id}: {errors[0]}")
    contact = arc[0][0]
    m.gripper(art.handle.width + 0.04)
    m.ignore = set()
    start = m.continuous_start(key, m.robot.q()[:2])
    if start is not None:
        try:
            m.move_joint(start)
        except SkillError as exc:  # the joint-space path meets something: straight moves instead
            if exc.failure is not Failure.BLOCKED:
                raise
    m.move_line((contact + back, quat))
    m.ignore_links = {(obj.body, obj.links[art.link])}
    m.move_line((contact, quat))
    m.ignore_links = set()
    if not m.grasp_close():
        raise SkillError(Failure.GRASP_MISSED, f"missed the door handle of {obj.id}")
    m.ignore = {obj.body}  # the door moves with the hand; the rest of the world is still checked
    for pose in arc[1:]:
        m.move_line(pose, check=True)
    m.step(30)
    m.release()
    pos, quat = m.pose()
    m.move_line((pos - approach_axis(quat) * 0.06 + np.array([0, 0, 0.04]), quat), check=False)
    m.ignore = set()


def _turn(world: World, m: Motion, obj: SimObject, part: str, art: Articulation, target: float) -> None:
    """Grasp a knob from above and turn it (with the wrist) to joint position ``target``."""
    import pybullet as p

    handle, yaw = _handle(world, obj, art)
    delta = target - world.joint_position(obj, part)
    lift(m, transit_height(world))
    # the hand is symmetric: of the grasp yaws a and a + pi, take one whose turned pose the wrist reaches
    # from some base position (parking is planned before anything moves)
    quat = goal = None
    for k in (0, -1, 1):
        a = yaw - math.pi / 2 + k * math.pi
        q_start = p.getQuaternionFromEuler((math.pi, 0, a))
        q_end = p.getQuaternionFromEuler((math.pi, 0, a + delta + math.copysign(KNOB_OVERSHOOT, delta)))
        above = handle + np.array([0, 0, APPROACH])
        try:
            m.park_for(handle, poses=[(handle, q_start), (handle, q_end), (above, q_start)])
        except SkillError:
            continue
        quat, goal = q_start, q_end
        break
    if quat is None or goal is None:
        raise SkillError(
            Failure.UNREACHABLE, f"the wrist cannot turn the knob of {obj.id} by {delta:.2f} rad"
        )
    m.ignore_links = {(obj.body, obj.links[art.link])}
    # arrive above the knob on the arm configuration from which the descent and the turn are continuous
    # (a straight move down from transit height can leave the reachable set on the way)
    above = handle + np.array([0, 0, APPROACH])
    start = m.continuous_start([(above, quat), (handle, quat), (handle, goal)], m.robot.q()[:2])
    if start is not None:
        try:
            m.move_joint(start)
        except SkillError as exc:
            if exc.failure is not Failure.BLOCKED:
                raise
    for attempt in range(2):  # a knob nudged by the closing fingers can slip out: look again, once
        m.gripper(0.06)
        m.move_line((handle + np.array([0, 0, APPROACH]), quat))
        m.move_line((handle, quat))
        if m.grasp_close():
            break
        m.gripper(0.06)
        m.move_line((handle + np.array([0, 0, APPROACH]), quat), check=False)
        if attempt == 1:
            raise SkillError(Failure.GRASP_MISSED, f"missed the knob of {obj.id} twice")
        handle, yaw = _handle(world, obj, art)
        delta = target - world.joint_position(obj, part)
        a = p.getEulerFromQuaternion(quat)[2]  # keep the chosen wrist branch; re-aim it at the bar
        a += ((yaw - math.pi / 2 - a + math.pi / 2) % math.pi) - math.pi / 2
        quat = p.getQuaternionFromEuler((math.pi, 0, a))
        goal = p.getQuaternionFromEuler((math.pi, 0, a + delta + math.copysign(KNOB_OVERSHOOT, delta)))
    m.ignore = {obj.body}
    m.move_line((handle, goal), check=False)
    m.step(20)
    m.release(0.06)
    m.move_line((handle + np.array([0, 0, APPROACH]), goal), check=False)
    m.ignore = set()
    m.ignore_links = set()


def _press(world: World, m: Motion, obj: SimObject, part: str, art: Articulation) -> None:
    """Press a button with the closed fingers and let it spring back."""
    top, _ = _handle(world, obj, art)
    # fingers side by side across the line to the object's centre: the hand stays clear of poles and walls
    lo, hi = world.body_aabb(obj.body)
    to_centre = (lo[:2] + hi[:2]) / 2 - top[:2]
    quat = top_down(math.atan2(to_centre[1], to_centre[0]) + math.pi / 2)
    lift(m, transit_height(world))
    m.park_for(top, poses=[(top, quat), (top - np.array([0, 0, abs(art.open - art.closed) + 0.004]), quat)])
    m.gripper(0.0, steps=30)
    m.move_line((top + np.array([0, 0, APPROACH]), quat))
    m.ignore = {obj.body}
    m.move_line((top - np.array([0, 0, abs(art.open - art.closed) + 0.004]), quat), check=False)
    m.step(30)
    m.move_line((top + np.array([0, 0, APPROACH]), quat), check=False)
    m.ignore = set()
    m.step(30)


def _stopped(world: World, obj: SimObject, part: str, art: Articulation) -> bool:
    """Whether the part rests against another object (a lid against a cabinet): moving it again is
    futile. What rides in or on the part (a mug in the drawer) does not count."""
    import pybullet as p

    link = obj.links[art.link]
    node = _node_of(world, obj, part)
    riders = {o.body for o in world.objects.values() if (support_of(world, o.id) or ("", ""))[1] == node}
    others = {o.body for o in world.objects.values()} - {obj.body} - riders
    # what rides on the part presses down on it; what stops it pushes sideways (a horizontal normal)
    return any(
        pt[2] in others and pt[3] == link and abs(pt[7][2]) < 0.5
        for pt in p.getContactPoints(obj.body, physicsClientId=world.client)
    )


#: A stroke that ends more than this fraction of the travel short is completed by a second one.
SHORT_STROKE = 0.1


def operate(world: World, m: Motion, node_id: str, kind: str) -> dict:
    """Open, close, turn on/off or press the part behind ``node_id``; checks the resulting joint state."""
    role = "open" if kind in ("open", "close") else "switch"
    found = world.articulation(node_id, role)
    if found is None:
        raise SkillError(Failure.UNSUPPORTED, f"{node_id} has no part to {kind.replace('_', ' ')}")
    obj, part, art = found
    if art.handle is None:
        raise SkillError(Failure.UNSUPPORTED, f"{node_id}: {part} has no handle")
    if kind in ("open", "close"):
        goal = art.open if kind == "open" else art.closed - 0.01 * np.sign(art.open - art.closed)
        if art.kind in ("drawer", "lid"):
            _slide(world, m, obj, part, art, float(goal))
            # a stroke that ended short (the tab slipped in the fingers, the push stopped early) leaves
            # a lid over part of the opening, or a drawer "closed" 9 cm out, in the way of the one
            # below it: once more for the rest, unless the part rests against something
            short = abs(float(goal) - world.joint_position(obj, part))
            if short > SHORT_STROKE * abs(art.open - art.closed) and not _stopped(world, obj, part, art):
                _slide(world, m, obj, part, art, float(goal))
        elif art.kind == "door":
            _swing(world, m, obj, part, art, float(goal))
        else:
            raise SkillError(Failure.UNSUPPORTED, f"opening a {art.kind} ({node_id}) is not implemented")
        m.step(30)
        now = art.is_open(world.joint_position(obj, part))
        if now != (kind == "open"):
            raise SkillError(Failure.NOT_ACHIEVED, f"{node_id} is still {'open' if now else 'closed'}")
        return {"joint": round(world.joint_position(obj, part), 4)}
    want = {"turn_on": True, "turn_off": False}.get(kind)
    if art.kind == "button":
        before = world.is_on(obj.id)
        if want is None or before != want:
            _press(world, m, obj, part, art)
        now = world.is_on(obj.id)
        if (want is not None and now != want) or (want is None and now == before):
            raise SkillError(Failure.NOT_ACHIEVED, f"pressing {node_id} did not switch it")
        return {"on": now}
    if art.kind == "knob" and want is not None:
        _turn(world, m, obj, part, art, art.open if want else art.closed)
        m.step(20)
        if world.is_on(obj.id) != want:
            raise SkillError(Failure.NOT_ACHIEVED, f"{node_id} is still {'on' if not want else 'off'}")
        return {"on": want, "joint": round(world.joint_position(obj, part), 4)}
    raise SkillError(Failure.UNSUPPORTED, f"cannot {kind} {node_id} ({art.kind})")


def _push_leg(
    world: World, m: Motion, obj: SimObject, goal: np.ndarray, committed: bool, inside: bool = False
) -> None:
    """Slide ``obj`` in a straight line until its centre reaches ``goal`` (x, y); approach checked first.

    ``inside``: for hollow objects (plates, bowls, boxes) the closed fingers go down inside and push
    the far wall from within, so no free space is needed behind the object.
    """
    lo, hi = world.body_aabb(obj.body)
    centre = (lo + hi) / 2
    d = goal - centre[:2]
    dist = float(np.linalg.norm(d))
    if dist < 0.005:
        return
    u = d / dist
    radius = float(abs(u[0]) * (hi[0] - lo[0]) / 2 + abs(u[1]) * (hi[1] - lo[1]) / 2)
    quat = top_down(math.atan2(u[1], u[0]) + math.pi / 2)  # fingers side by side across the push direction
    if inside:
        z = lo[2] + 0.03  # the fingertips reach 1 cm below the grasp point: keep them off the floor
        start = np.array([centre[0], centre[1], z])
        end = np.array([*(goal + u * (radius - 0.02)), z])
    else:
        z = lo[2] + min(0.02, (hi[2] - lo[2]) * 0.5)
        # tall objects: the hand (3 cm thick) above the fingers must stay clear of the object too
        standoff = 0.03 if hi[2] - lo[2] < 0.06 else 0.048
        start = np.array([*(centre[:2] - u * (radius + standoff)), z])
        end = start + np.array([*(u * (dist + 0.012)), 0.0])
    above = start + np.array([0, 0, 0.12])
    z_transit = max(transit_height(world), above[2])
    lift(m, z_transit)
    m.park_for((start + end) / 2, poses=[(start, quat), (end, quat), (above, quat)])
    m.gripper(0.0, steps=30)
    m.move_line((np.array([start[0], start[1], z_transit]), quat))
    m.move_line((above, quat))
    m.move_line((start, quat))
    m.ignore = {obj.body}
    m.move_line((end, quat), check=False)
    m.step(20)
    pos, _ = m.pose()
    m.move_line((pos - np.array([*(u * 0.03), -0.1]), quat), check=False)
    m.ignore = set()
    m.step(40)
    del committed  # kept for readability at the call sites: later legs' failures are real failures


def push(world: World, m: Motion, node_id: str, to: str) -> dict | None:
    """Slide an object along the table into region ``to`` (or out of its region onto the table)."""
    if node_id not in world.objects:
        raise SkillError(Failure.UNSUPPORTED, f"{node_id} is not a movable object")
    obj = world.objects[node_id]
    lo, hi = world.body_aabb(obj.body)
    centre = (lo + hi) / 2
    if to in world.regions:
        r = world.regions[to]
        goal = np.array([(r.bounds[0] + r.bounds[2]) / 2, (r.bounds[1] + r.bounds[3]) / 2])
    elif to == world.table_id:
        # out of the current region: towards the robot, past the region's near edge
        region = next(
            (reg for nid, reg in world.regions.items() if support_of(world, node_id) == ("on", nid)), None
        )
        if region is None:
            raise SkillError(Failure.UNSUPPORTED, f"{node_id} is not in a region to push it out of")
        goal = np.array([region.bounds[0] - (hi[0] - lo[0]) / 2 - 0.03, centre[1]])
    else:
        raise SkillError(Failure.UNSUPPORTED, f"cannot push onto {to}: not a region of the table")
    # a straight push, else an L-shaped one (x then y, or y then x) when the straight one's start is
    # blocked (a cabinet behind the object) or out of reach; the first leg that moves anything commits
    corners = [goal, np.array([goal[0], centre[1]]), np.array([centre[0], goal[1]])]
    plans: list[tuple[list[np.ndarray], bool]] = [
        ([goal], False),
        ([corners[1], goal], False),
        ([corners[2], goal], False),
    ]
    if "" in obj.model.interiors:  # hollow: it can be pushed from inside
        plans.insert(1, ([goal], True))
    errors: list[str] = []
    for legs, inside in plans:
        try:
            _push_leg(world, m, obj, legs[0], committed=False, inside=inside)
        except SkillError as exc:
            if exc.failure not in (Failure.BLOCKED, Failure.UNREACHABLE):
                raise
            errors.append(exc.message)
            continue
        for leg in legs[1:]:
            _push_leg(world, m, obj, leg, committed=True, inside=inside)
        break
    else:
        raise SkillError(
            Failure.BLOCKED, f"no push of {node_id} towards {to} can start: " + "; ".join(errors[:3])
        )
    got = support_of(world, node_id)
    if got != ("on", to):
        raise SkillError(Failure.NOT_ACHIEVED, f"{node_id} ended {got}, not on {to}")
    return {"support": f"on {to}"}


def roofed_opening(world: World, target: str, obj: SimObject) -> tuple[np.ndarray, np.ndarray] | None:
    """For a container whose interior has a roof (a microwave): ``(staging spot, inward direction)``,
    where the held ``obj`` is set down on the table in front of the opening (its bottom centre) and the
    way it is then pushed in; None for containers open from above (or when the staging spot is taken).

    A hand coming from above cannot reach under a roof, so the object is set down outside and slid in.
    The opening is the model's front (local -x), where doors open.
    """
    import pybullet as p

    if target not in world.objects:
        return None
    host = world.objects[target]
    interior = host.model.interiors.get("")
    if interior is None:
        return None
    link = host.links[interior.link]
    centre = world.to_world(host.body, link, interior.center)
    top = centre[2] + interior.size[2] / 2
    hit = p.rayTest((centre[0], centre[1], top + 0.3), tuple(centre), physicsClientId=world.client)[0]
    if hit[0] != host.body or hit[3][2] < top - 0.02:
        return None  # open from above: nothing over the interior
    yaw = world.yaw_of(host.body, link)
    inward = np.array([math.cos(yaw), math.sin(yaw)])
    front = centre[:2] - inward * interior.size[0] / 2
    lo, hi = world.body_aabb(obj.body)
    half = float(abs(inward[0]) * (hi[0] - lo[0]) / 2 + abs(inward[1]) * (hi[1] - lo[1]) / 2)
    spot = front - inward * (half + 0.035)
    z = world.layout.table_height
    # the staging spot must be free table: nothing there but the table
    ray = p.rayTest((spot[0], spot[1], z + 0.3), (spot[0], spot[1], z - 0.01), physicsClientId=world.client)[
        0
    ]
    if ray[0] != world.table_body:
        return None
    return np.array([spot[0], spot[1], z]), inward


def push_in(world: World, m: Motion, obj: SimObject, inward: np.ndarray, target: str) -> None:
    """Slide ``obj`` (standing in front of ``target``'s opening) in along ``inward`` until most of it is
    inside; the hand stays outside the opening (its wrist would meet the roof)."""
    host = world.objects[target]
    interior = host.model.interiors[""]
    centre = world.to_world(host.body, host.links[interior.link], interior.center)
    front = centre[:2] - inward * interior.size[0] / 2
    lo, hi = world.body_aabb(obj.body)
    half = float(abs(inward[0]) * (hi[0] - lo[0]) / 2 + abs(inward[1]) * (hi[1] - lo[1]) / 2)
    # all of it past the opening ("in" needs half of it inside; the pushed object lags the hand)
    goal = front + inward * (half + 0.01)
    _push_leg(world, m, obj, goal, committed=True)
