"""Where to put an object into a container so that several fit: spots in the container's own frame.

A box may stand at any yaw and so may the objects going into it. Reasoning with world-aligned boxes
wastes most of the floor, so the spot is chosen in the container's frame, with the held object turned
(the wrist rotates by ``delta``, at most 45 degrees, or a quarter turn more when only that way round
it fits, or when the quarter turn packs better in a drawer) to line up with the container's walls.

Three rectangles are kept free, each in the container's frame:

* the object's own footprint, from its collision shapes (a mug's handle sticks out on one side only:
  its footprint is 4.4 x 7.4 cm, not a 10.4 cm square), half a centimetre round it;
* the fingers: centred on the grasp point, their measured reach along the closing axis (outer faces,
  opened a little to let go) and their thickness across it;
* the hand's whole 22 x 9.4 cm footprint, centred on the grasp point, wherever something stands taller
  than the hand's underside at release (the carcass around an open drawer, the drawer above and its
  pull bar, a milk carton, the box's own open lid).

Candidates are the grid of the free floor plus every position that touches a wall or a neighbour
(bottom-left fill), so objects are set side by side as tight as the fingers allow. Of the free ones,
a drawer's deepest row (next to the carcass) fills first, which leaves its front free for the hand and
the next objects; any other container's row nearest the robot, the easiest to reach. A drawer is
packed in the part that sticks out of its cabinet: the cabinet's other links are obstacles shape by
shape (a pull bar is a 1.2 cm bar, not the whole width of the drawer above). When the floor is full
the object goes on the lowest neighbour: a second layer (never on the cabinet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from gsr.skills.asset_model import AssetModel, Interior
from gsr.skills.sim_graph import support_of
from gsr.skills.world import SimObject, World

GAP_CLOSING, GAP_ACROSS = 0.018, 0.005
#: Half the Panda hand's footprint from the grasp point (m): along the closing axis, across it
#: (measured from the hand link's bounding box: 21.7 x 9.4 cm)
HAND_HALF = (0.109, 0.047)
#: Half a finger's thickness across the closing axis (m; the finger links are 2.0 cm wide).
FINGER_HALF = 0.011
#: How much the fingers open to let go (m, both together; ``grasping.place`` opens by 1.6 cm).
RELEASE_OPEN = 0.016
#: Extra room between the hand and a fixture (carcass, the drawer above): a hand that grazes it is
#: stopped by the motion checker.
FIXTURE_ROOM = 0.008
#: Rows closer than this (m) count as one row when choosing the next spot.
ROW = 0.006
#: How many further objects like the held one the choice of a spot looks ahead for.
LOOKAHEAD = 6
#: How high above the container's floor the fingertips are when the object is let go (m).
FINGERTIP = 0.01
#: Half the thickness (m) of the strips that stand for a container's walls round its interior.
WALL = 0.005
#: How much higher (m) than its release point the hand may stop on a wall top and let go (the place
#: skill allows 6 cm; 1.5 cm of it kept as margin for the estimate of the hand's underside).
WALL_DROP = 0.045

#: An axis-aligned rectangle in the container's frame: centre (u, v), half sizes, top height (m).
Rect = tuple[np.ndarray, np.ndarray, float]


def container_of(world: World, target: str) -> tuple[SimObject, Interior, int, bool] | None:
    """The object, interior, interior link and whether it is a drawer, behind a container node."""
    found = world.interior_of(target)
    if found is None:
        return None
    o, part, interior = found
    art = o.model.articulations.get(part) if part else None
    if art is not None and art.kind != "drawer":
        return None
    return o, interior, o.links[interior.link], art is not None


def footprint(model: AssetModel) -> tuple[np.ndarray, np.ndarray]:
    """``(centre, half)``: the rectangle (x, y, in the model's own frame) its base link's collision
    shapes cover; the symmetric ``extent`` when the model has no shapes to measure."""
    shapes = [s for s in model.links[0].shapes if s.collide] if model.links else []
    if not shapes:
        return np.zeros(2), np.array(model.extent[:2]) / 2
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for s in shapes:
        if s.kind == "cylinder":
            half = np.array([s.size[0], s.size[0]])
        else:
            c, si = abs(math.cos(s.rpy[2])), abs(math.sin(s.rpy[2]))
            half = np.array([c * s.size[0] + si * s.size[1], si * s.size[0] + c * s.size[1]]) / 2
        lo = np.minimum(lo, np.array(s.xyz[:2]) - half)
        hi = np.maximum(hi, np.array(s.xyz[:2]) + half)
    return (lo + hi) / 2, (hi - lo) / 2


def _half(size: np.ndarray | tuple[float, ...], rel_yaw: float) -> np.ndarray:
    """Half sizes, along the container's axes, of a rectangle of full ``size`` turned by ``rel_yaw``."""
    c, s = abs(math.cos(rel_yaw)), abs(math.sin(rel_yaw))
    return np.array([c * size[0] / 2 + s * size[1] / 2, s * size[0] / 2 + c * size[1] / 2])


def _fixture_rects(
    world: World, cont: SimObject, link: int, rot: np.ndarray, centre: np.ndarray, floor: float
) -> list[Rect]:
    """The rest of a drawer's cabinet (carcass, the other drawers, their pull bars) as obstacles in the
    drawer's frame, shape by shape: a drawer is only open over the part that sticks out, and the closed
    drawer above it, its pull bar and the carcass front stand higher than the hand's underside there."""
    import pybullet as p

    children = {link}
    n = p.getNumJoints(cont.body, physicsClientId=world.client)
    for j in range(n):  # links hanging from the drawer (its handle) move with it
        if p.getJointInfo(cont.body, j, physicsClientId=world.client)[16] in children:
            children.add(j)
    out = []
    for model_link in cont.model.links:
        j = cont.links.get(model_link.name, -1)
        if j in children:
            continue
        pos, quat = world.link_pose(cont.body, j)
        lrot = np.array(p.getMatrixFromQuaternion(list(quat))).reshape(3, 3)
        for s in model_link.shapes:
            if not s.collide:
                continue
            hx, hy, hz = (
                (s.size[0], s.size[0], s.size[2] / 2) if s.kind == "cylinder" else np.array(s.size) / 2
            )
            cs, sn = math.cos(s.rpy[2]), math.sin(s.rpy[2])
            corners = []
            for dx in (-hx, hx):
                for dy in (-hy, hy):
                    for dz in (-hz, hz):
                        local = np.array(s.xyz) + np.array([cs * dx - sn * dy, sn * dx + cs * dy, dz])
                        corners.append(pos + lrot @ local)
            pts = np.array(corners)
            if pts[:, 2].max() < floor + 0.005:
                continue
            uv = (pts[:, :2] - centre[:2]) @ rot  # rot.T @ (p - c) for every corner
            lo, hi = uv.min(axis=0), uv.max(axis=0)
            out.append(((lo + hi) / 2, (hi - lo) / 2, float(pts[:, 2].max())))
    return out


#: How far a finger's outer face lies beyond its pad, along the closing axis (measured on PyBullet's
#: Panda model: with the fingers shut each finger reaches 3.04 cm from the grasp point).
FINGER_OUTER = 0.031


def finger_reach(world: World) -> float:
    """How far the fingers reach from the grasp point along the closing axis now (outer faces, m)."""
    return world.robot.finger_width() / 2 + FINGER_OUTER


def fitting_turn(
    extent: tuple[float, float, float], rel: float, delta: float, half_room: tuple[float, float]
) -> float:
    """The wrist turn that lines the object up with the walls *and* fits it in: ``delta`` (the
    smallest turn) when the object's footprint fits the room that way round, else the quarter turn
    more or less that does (a 13 cm book into a long narrow compartment), else ``delta``."""
    for d in sorted((delta, delta + math.pi / 2, delta - math.pi / 2), key=abs):
        held = _half(extent, rel + d)
        if held[0] + GAP_ACROSS <= half_room[0] and held[1] + GAP_ACROSS <= half_room[1]:
            return d
    return delta


#: Room (rad) kept from the wrist joint's limits when turning the held object.
WRIST_ROOM = 0.15


def _wrist_can(world: World, delta: float) -> bool:
    """Whether the wrist's last joint can turn the hand (pointing down) by ``delta`` about the vertical
    (the joint turns the other way round, so a yaw of +d is a joint move of -d)."""
    robot = world.robot
    q7 = float(robot.q()[8]) - delta
    return robot.lower[8] + WRIST_ROOM <= q7 <= robot.upper[8] - WRIST_ROOM


@dataclass(frozen=True)
class _Held:
    """The held object and hand for one wrist turn, in the container's frame, relative to the spot."""

    delta: float
    body: np.ndarray  # half size of the object's footprint (the spot is its centre)
    grasp: np.ndarray  # the grasp point's offset from the spot
    fingers: np.ndarray  # half size of the fingers' rectangle round the grasp point (opened to let go)
    closed: np.ndarray  # the same while they still hold the object (they open only at the bottom)
    hand: np.ndarray  # half size of the hand's footprint round the grasp point


def _held(
    world: World, obj: SimObject, yaw: float, closing_yaw: float, delta: float, width: float | None = None
) -> _Held:
    """The held object and the hand for the wrist turn ``delta``; ``width``: the fingers' opening to
    assume (a fresh grasp of a later object) instead of the one they have now."""
    size = 2 * footprint(obj.model)[1]
    body = _half(size, world.yaw_of(obj.body) - yaw + delta)
    lo, hi = world.body_aabb(obj.body)
    off = world.robot.ee_pose()[0][:2] - (lo[:2] + hi[:2]) / 2
    if float(np.linalg.norm(off)) > 0.15:  # not in the hand (a planning query): held at its origin
        off = world.link_pose(obj.body, -1)[0][:2] - (lo[:2] + hi[:2]) / 2
    c, s = math.cos(delta - yaw), math.sin(delta - yaw)
    grasp = np.array([c * off[0] - s * off[1], s * off[0] + c * off[1]])
    e1 = closing_yaw + delta - yaw  # closing axis in the container frame
    ce, se = abs(math.cos(e1)), abs(math.sin(e1))
    reach = (finger_reach(world) if width is None else width / 2 + FINGER_OUTER) + RELEASE_OPEN / 2
    fingers = np.array([ce * reach + se * FINGER_HALF, se * reach + ce * FINGER_HALF])
    closed = fingers - RELEASE_OPEN / 2 * np.array([ce, se])
    hand = np.array([ce * HAND_HALF[0] + se * HAND_HALF[1], se * HAND_HALF[0] + ce * HAND_HALF[1]])
    return _Held(delta, body, grasp, fingers, closed, hand)


def _fresh_grasp(world: World, obj: SimObject, closing_yaw: float) -> tuple[float, float]:
    """``(closing yaw, finger opening)`` of a square grasp like the current one: the closing axis turned to
    the nearest of the object's own axes, the fingers on the footprint's size along it (its body's for
    a mug held across it: the handle sticks out along the other axis), never wider than they are now
    (a bowl held by its rim)."""
    own = world.yaw_of(obj.body)
    k = round((closing_yaw - own) / (math.pi / 2))
    size = 2 * footprint(obj.model)[1]
    return own + k * math.pi / 2, min(float(size[k % 2]), world.robot.finger_width())


def _overlaps(points: np.ndarray, half: np.ndarray, rects: list[Rect]) -> np.ndarray:
    """For each point (N x 2), whether the rectangle ``half`` round it overlaps any of ``rects``."""
    if not rects:
        return np.zeros(len(points), dtype=bool)
    oc = np.array([r[0] for r in rects])
    oh = np.array([r[1] for r in rects])
    d = np.abs(points[:, None, :] - oc[None, :, :])
    return np.any(np.all(d < half[None, None, :] + oh[None, :, :] - 1e-6, axis=2), axis=1)


def _candidates(
    h: _Held,
    lo: np.ndarray,
    hi: np.ndarray,
    half_room: np.ndarray,
    obstacles: list[Rect],
    tall: list[Rect],
    n: int = 13,
) -> np.ndarray:
    """Spots to try: a grid over ``lo..hi`` and every position touching a wall or an obstacle."""
    wall = half_room - h.closed
    axes = []
    for k in range(2):
        vals = [*np.linspace(lo[k], hi[k], n)]
        for oc, oh, _top in obstacles:
            for half, off in ((h.body + GAP_ACROSS, 0.0), (h.fingers, h.grasp[k])):
                vals += [oc[k] - oh[k] - half[k] - off - 1e-4, oc[k] + oh[k] + half[k] - off + 1e-4]
        for oc, oh, _top in tall:
            vals += [
                oc[k] - oh[k] - h.hand[k] - h.grasp[k] - 1e-4,
                oc[k] + oh[k] + h.hand[k] - h.grasp[k] + 1e-4,
            ]
        # the fingers against a wall
        vals += [-wall[k] - h.grasp[k] + 1e-4, wall[k] - h.grasp[k] - 1e-4]
        arr = np.array(vals)
        axes.append(np.unique(np.round(arr[(arr >= lo[k] - 1e-9) & (arr <= hi[k] + 1e-9)], 5)))
    uu, vv = np.meshgrid(axes[0], axes[1], indexing="ij")
    return np.stack([uu.ravel(), vv.ravel()], axis=1)


def packed_spot(
    world: World, obj: SimObject, target: str, closing_yaw: float
) -> tuple[np.ndarray, float] | None:
    """``(spot, delta)``: the held object's footprint centre (x, y) and bottom height inside ``target``,
    and the wrist turn; None if ``target`` is no container this packs.

    ``closing_yaw`` is the world direction the fingers close along now; the room the fingers need
    beside the object is measured from the finger links, not assumed.
    """
    found = container_of(world, target)
    if found is None:
        return None
    cont, interior, link, drawer = found
    yaw = world.yaw_of(cont.body, link)
    centre = world.to_world(cont.body, link, interior.center)
    half_room = np.array(interior.size[:2]) / 2
    floor = centre[2] - interior.size[2] / 2
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    fixed = _fixture_rects(world, cont, link, rot, centre, floor) if drawer else []
    movable = _movable_rects(world, obj, cont, rot, centre, half_room, floor)
    # the container's own walls: the hand may reach over them only where it stops at most a few
    # centimetres higher than it would let go (a 3 cm cube in an 8.5 cm box: let go 3-4 cm up; a
    # small package in a deep basket: the hand must go down between the walls)
    rim = float(world.aabb(cont.body, link)[1][2])
    walls = [
        (np.array([sx * (half_room[0] + WALL), 0.0]), np.array([WALL, half_room[1] + 2 * WALL]), rim)
        for sx in (-1, 1)
    ] + [
        (np.array([0.0, sy * (half_room[1] + WALL)]), np.array([half_room[0] + 2 * WALL, WALL]), rim)
        for sy in (-1, 1)
    ]
    high = [w for w in walls if w[2] - (floor + obj.model.extent[2] + 0.02) > WALL_DROP]
    # which row fills first: a drawer's deepest (next to the carcass, the front stays free for the
    # hand); any other container's nearest the robot (-x), the easiest to reach (a basket's far side
    # was out of the arm's reach from every base spot)
    if drawer:
        part = world.parts[target][1]
        far_world = -world.joint_axis(cont, part)[:2]
    else:
        far_world = np.array([-1.0, 0.0])
    far = rot.T @ far_world
    k_row = int(np.argmax(np.abs(far)))
    sign = 1.0 if far[k_row] > 0 else -1.0
    # turn the held object (by the wrist) so its sides run along the container's walls
    rel = world.yaw_of(obj.body) - yaw
    delta = -(((rel + math.pi / 4) % (math.pi / 2)) - math.pi / 4)
    size = tuple(2 * footprint(obj.model)[1])
    first = fitting_turn((*size, 0.0), rel, delta, tuple(half_room))
    # the hand may also turn a quarter more (a drawer: its 22 cm length then runs along the cabinet's
    # front instead of reaching under the closed drawer above); a turn the wrist's last joint cannot
    # make is left out (a half turn was tried too: the arm then found no base spot for the turned hand)
    turns = [delta, delta + math.pi / 2, delta - math.pi / 2]
    deltas = [first] + [d for d in turns if abs(d - first) > 1e-6 and _wrist_can(world, d)]
    # of the spots each turn allows (the best of the first and of the last row), the lowest rank, then
    # the one that leaves room for the most further objects like this one (a mug whose handle can only
    # point out of the drawer goes in the front row, so the back row still takes the others), then
    # the row that fills first, then (outside drawers) the turn that fits first, then the smallest turn
    top = floor + float(world.body_aabb(obj.body)[1][2] - world.body_aabb(obj.body)[0][2])
    # the further objects like this one as a fresh grasp holds them: the fingers closed square across
    # the object's body on its width, not aslant or opened wider as this one may happen to be held (a
    # mug taken 30 deg off its axis needs 4 cm more room for the fingers; one gripped 5 mm wider, 2.5
    # mm more on each side: the look-ahead then counted the room of a layout it could not keep)
    fresh_closing, fresh_width = _fresh_grasp(world, obj, closing_yaw)
    future = [_held(world, obj, yaw, fresh_closing, first + k * math.pi / 2, fresh_width) for k in range(4)]
    best: tuple[tuple, np.ndarray, float] | None = None
    for d in deltas:
        h = _held(world, obj, yaw, closing_yaw, d)
        for rank, row, uv in _floor_spots(h, half_room, floor, obj, fixed, movable, k_row, sign, high):
            placed = [*movable, (uv, h.body, top)]
            more = _fill_count(
                future, half_room, floor, obj, fixed, placed, k_row, sign, high, LOOKAHEAD, rank
            )
            key = (rank, -more, row, 0.0 if drawer else abs(d - first), abs(d))
            if best is None or key < best[0]:
                best = (key, uv, d)
    if best is not None:
        uv, d = best[1], best[2]
        xy = centre[:2] + rot @ uv
        return np.array([xy[0], xy[1], floor]), d
    # the floor is full: a second layer, on the lowest things there (never on the cabinet)
    h = _held(world, obj, yaw, closing_yaw, first)
    uv, z = _layer_spot(h, half_room, floor, fixed, movable)
    xy = centre[:2] + rot @ uv
    return np.array([xy[0], xy[1], z]), first


def _movable_rects(
    world: World,
    obj: SimObject,
    cont: SimObject,
    rot: np.ndarray,
    centre: np.ndarray,
    half_room: np.ndarray,
    floor: float,
) -> list[Rect]:
    """What stands in or near the container (not the held object, not fixtures), by true footprint; and
    the container's own open lid (slid off beside it at rim height)."""
    yaw = math.atan2(rot[1, 0], rot[0, 0])
    out: list[Rect] = []
    for o in world.objects.values():
        if o.id in (obj.id, cont.id) or o.model.fixed or support_of(world, o.id) == ("held", ""):
            continue
        lo, hi = world.body_aabb(o.body)
        local = rot.T @ ((lo[:2] + hi[:2]) / 2 - centre[:2])
        if np.any(np.abs(local) > half_room + HAND_HALF[0] + 0.05) or hi[2] < floor - 0.005:
            continue
        half = _half(2 * footprint(o.model)[1], world.yaw_of(o.body) - yaw)
        # a tipped-over object: its world box is the better guess
        if hi[2] - lo[2] < 0.7 * o.model.extent[2]:
            corners = [
                rot.T @ (np.array([x, y]) - centre[:2]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
            ]
            half = (np.max(corners, axis=0) - np.min(corners, axis=0)) / 2
        out.append((local, half, float(hi[2])))
    for part, art in cont.model.articulations.items():
        if art.kind == "lid" and art.is_open(world.joint_position(cont, part)):
            lo, hi = world.aabb(cont.body, cont.links[art.link])
            corners = [
                rot.T @ (np.array([x, y]) - centre[:2]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
            ]
            clo, chi = np.min(corners, axis=0), np.max(corners, axis=0)
            out.append(((clo + chi) / 2, (chi - clo) / 2, float(hi[2])))
    return out


def _floor_spots(
    h: _Held,
    half_room: np.ndarray,
    floor: float,
    obj: SimObject,
    fixed: list[Rect],
    movable: list[Rect],
    k_row: int,
    sign: float,
    walls: list[Rect],
    rows: int = 2,
    grid: int = 13,
) -> list[tuple[int, float, np.ndarray]]:
    """``(rank, row key, spot)`` of the best floor spot in the row that fills first for one wrist turn
    and (with ``rows`` > 1) of the row that fills last; empty when the floor has no room for the object
    and the fingers. Rank 0: room for the fingers and the whole hand; higher: by how much higher the
    hand would stop on what its fingers or its footprint meet (2 cm steps). ``walls``: the container's
    own walls where they are too high for the hand to reach over them (they count for the hand only:
    the fingers stay inside anyway)."""
    lo = -half_room + h.body + GAP_ACROSS
    hi = half_room - h.body - GAP_ACROSS
    if np.any(lo > hi + 1e-9):
        return []
    # what stands higher than the hand's underside at release needs the hand's whole footprint clear
    hand_bottom = floor + obj.model.extent[2] + 0.02
    tall_fixed = [r for r in fixed if r[2] > hand_bottom]
    tall_movable = [r for r in movable if r[2] > hand_bottom] + walls
    obstacles = fixed + movable
    pts = _candidates(h, lo, hi, half_room, obstacles, tall_fixed + tall_movable, grid)
    # the fingers stay inside the walls and off the cabinet, the object off everything, the hand off
    # the cabinet (with a little room)
    g = pts + h.grasp
    # (the fingers open a little at the bottom: against a wall that pushes nothing)
    inside = np.all(np.abs(g) <= half_room - h.closed + 1e-9, axis=1)
    ok = inside & ~_overlaps(pts, h.body + GAP_ACROSS, obstacles) & ~_overlaps(g, h.fingers, fixed)
    ok &= ~_overlaps(g, h.hand + FIXTURE_ROOM, tall_fixed)
    # fingers over a neighbour stop on its top and let go that much higher: allowed up to WALL_DROP
    finger_top = _highest_met(g, h.fingers, movable)
    ok &= finger_top - (floor + FINGERTIP) <= WALL_DROP
    if not np.any(ok):
        return []
    pts, g, finger_top = pts[ok], g[ok], finger_top[ok]
    # rank: 0 with room for the fingers and the whole hand, else by how much higher the hand stops on
    # what it meets (2 cm steps: a neighbour under the fingers, a basket's wall, a milk carton beside it)
    hand_top = _highest_met(g, h.hand, tall_movable)
    excess = np.maximum(finger_top - (floor + FINGERTIP), hand_top - hand_bottom)
    rank = np.where(np.isfinite(excess), 1 + np.round(np.maximum(excess, 0.0) / 0.02), 0).astype(int)
    # the first row first, then along the row from one side
    row = np.round(-sign * pts[:, k_row] / ROW)
    order = np.lexsort((pts[:, 1 - k_row], row, rank))
    i = int(order[0])
    out = [(int(rank[i]), float(row[i]), pts[i])]
    if rows > 1:  # and the best spot of the nearest row (of the same rank)
        same = order[rank[order] == rank[i]]
        last = same[row[same] == row[same].max()]
        j = int(last[np.argmin(pts[last, 1 - k_row])])
        if row[j] != row[i]:
            out.append((int(rank[j]), float(row[j]), pts[j]))
    return out


def _highest_met(points: np.ndarray, half: np.ndarray, rects: list[Rect]) -> np.ndarray:
    """For each point, the top of the highest of ``rects`` the rectangle ``half`` round it meets
    (-inf when it meets none)."""
    if not rects:
        return np.full(len(points), -np.inf)
    oc = np.array([r[0] for r in rects])
    oh = np.array([r[1] for r in rects])
    meets = np.all(np.abs(points[:, None, :] - oc[None]) < half[None, None, :] + oh[None] - 1e-6, axis=2)
    return np.where(meets, np.array([r[2] for r in rects])[None, :], -np.inf).max(axis=1)


def _fill_count(
    helds: list[_Held],
    half_room: np.ndarray,
    floor: float,
    obj: SimObject,
    fixed: list[Rect],
    movable: list[Rect],
    k_row: int,
    sign: float,
    walls: list[Rect],
    limit: int,
    max_rank: int = 0,
) -> int:
    """How many more objects like the held one (any of ``helds``' turns) still fit on the floor with the
    hand's room (spots of rank ``max_rank`` at most), set one by one at the best spot (at most ``limit``)."""
    placed = list(movable)
    top = floor + obj.model.extent[2]
    for n in range(limit):
        found = None
        for h in helds:
            spots = _floor_spots(h, half_room, floor, obj, fixed, placed, k_row, sign, walls, rows=1, grid=7)
            if spots and spots[0][0] <= max_rank and (found is None or spots[0][1] < found[0]):
                found = (spots[0][1], spots[0][2], h)
        if found is None:
            return n
        placed.append((found[1], found[2].body, top))
    return limit


def _layer_spot(
    h: _Held, half_room: np.ndarray, floor: float, fixed: list[Rect], movable: list[Rect]
) -> tuple[np.ndarray, float]:
    """A spot on top of the lowest neighbours (a second layer) and the height to let go at."""
    lo = -half_room + h.body + GAP_ACROSS
    hi = np.maximum(half_room - h.body - GAP_ACROSS, lo)
    grid = np.array([[u, v] for u in np.linspace(lo[0], hi[0], 13) for v in np.linspace(lo[1], hi[1], 13)])
    reach = np.maximum(h.body + GAP_ACROSS, h.fingers)
    layer = grid[~_overlaps(grid, reach, fixed)] if fixed else grid
    if len(layer) == 0:
        layer = grid

    def top(c: np.ndarray) -> float:
        tops = [t for oc, oh, t in movable if np.all(np.abs(c - oc) < reach + oh)]
        return max(tops, default=-np.inf)

    best = min(layer, key=lambda c: (round(top(c), 3), -abs(c[0]) - abs(c[1])))
    z = top(best)
    return best, (z + 0.003 if np.isfinite(z) else floor)
