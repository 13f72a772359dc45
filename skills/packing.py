"""Where to put an object into a container so that several fit: spots in the container's own frame.

A box may stand at any yaw and so may the cubes going into it. Reasoning with world-aligned boxes
wastes most of the floor, so the spot is chosen in the container's frame, with the held object turned
(the wrist rotates by ``delta``, at most 45 degrees, or up to 135 when only the other way round fits)
to line up with the container's walls. Along the fingers' closing axis the fingers need their
measured reach beside the object; across it half a centimetre.
When the floor is full the object goes on the lowest neighbour: a second layer.

A drawer is packed the same way, in the part that sticks out of its cabinet: the carcass and the
other drawers (pull bars included) are obstacles taller than the hand's underside, so the hand's
whole 22 x 9.4 cm footprint keeps clear of them; the wrist may also turn a quarter more so that the
hand's length runs along the cabinet's front.
"""

from __future__ import annotations

import math

import numpy as np
from gsr.skills.asset_model import Interior
from gsr.skills.sim_graph import support_of
from gsr.skills.world import SimObject, World

GAP_CLOSING, GAP_ACROSS = 0.018, 0.005
#: Half the Panda hand's footprint from the grasp point (m): along the closing axis, across it
#: (measured from the hand link's bounding box: 21.7 x 9.4 cm)
HAND_HALF = (0.109, 0.047)


def _container(world: World, target: str) -> tuple[SimObject, Interior, int, bool] | None:
    """The object, interior, interior link and whether it is a drawer, behind a container node."""
    drawer = False
    if target in world.objects:
        o = world.objects[target]
        interior = o.model.interiors.get("")
    elif target in world.parts:
        obj_id, part = world.parts[target]
        o = world.objects[obj_id]
        art = o.model.articulations.get(part)
        if art is not None and art.kind != "drawer":
            return None
        drawer = art is not None
        interior = o.model.interiors.get(part)
    else:
        return None
    return (o, interior, o.links[interior.link], drawer) if interior is not None else None


def _carcass(
    world: World, cont: SimObject, link: int, rot: np.ndarray, centre: np.ndarray, floor: float
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """The rest of a drawer's cabinet (carcass, the other drawers) as obstacles in the drawer's frame:
    a drawer is only open over the part that sticks out, and the closed drawer above it and the carcass
    front stand higher than the hand's underside there."""
    import pybullet as p

    out = []
    children = {link}
    n = p.getNumJoints(cont.body, physicsClientId=world.client)
    for j in range(n):  # links hanging from the drawer (its handle) move with it
        if p.getJointInfo(cont.body, j, physicsClientId=world.client)[16] in children:
            children.add(j)
    for j in range(-1, n):
        if j in children:
            continue
        lo, hi = world.aabb(cont.body, j)
        if hi[2] < floor + 0.005:
            continue
        corners = [rot.T @ (np.array([x, y]) - centre[:2]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
        clo, chi = np.min(corners, axis=0), np.max(corners, axis=0)
        out.append(((clo + chi) / 2, (chi - clo) / 2, float(hi[2])))
    return out


def _half(extent: tuple[float, float, float], rel_yaw: float) -> np.ndarray:
    c, s = abs(math.cos(rel_yaw)), abs(math.sin(rel_yaw))
    return np.array([c * extent[0] / 2 + s * extent[1] / 2, s * extent[0] / 2 + c * extent[1] / 2])


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


def packed_spot(
    world: World, obj: SimObject, target: str, closing_yaw: float
) -> tuple[np.ndarray, float] | None:
    """``(spot, delta)``: the held object's bottom centre inside ``target`` and the wrist turn; None if n/a.

    ``closing_yaw`` is the world direction the fingers close along now; the room the fingers need
    beside the object is measured from the finger links, not assumed.
    """
    found = _container(world, target)
    if found is None:
        return None
    cont, interior, link, drawer = found
    yaw = world.yaw_of(cont.body, link)
    centre = world.to_world(cont.body, link, interior.center)
    hu, hv = interior.size[0] / 2, interior.size[1] / 2
    floor = centre[2] - interior.size[2] / 2
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    # turn the held object (by the wrist) so its sides run along the container's walls
    rel = world.yaw_of(obj.body) - yaw
    delta = -(((rel + math.pi / 4) % (math.pi / 2)) - math.pi / 4)
    fixed = _carcass(world, cont, link, rot, centre, floor) if drawer else []
    # a drawer: the hand may also turn a quarter more, so that its 22 cm length runs along the
    # cabinet's front instead of reaching under the closed drawer above
    deltas = [delta, delta + math.pi / 2, delta - math.pi / 2] if drawer else [delta]
    best = None
    for d in deltas:
        found_spot = _spot_for(world, obj, cont, closing_yaw, yaw, rot, centre, (hu, hv), floor, d, fixed)
        key = (found_spot[2], abs(d))
        if best is None or key < best[0]:
            best = (key, found_spot[0], found_spot[1])
    assert best is not None
    return best[1], best[2]


def _spot_for(
    world: World,
    obj: SimObject,
    cont: SimObject,
    closing_yaw: float,
    yaw: float,
    rot: np.ndarray,
    centre: np.ndarray,
    half_size: tuple[float, float],
    floor: float,
    delta: float,
    fixed: list[tuple[np.ndarray, np.ndarray, float]],
) -> tuple[np.ndarray, float, int]:
    """``(spot, delta, rank)`` for one wrist turn ``delta``; rank 0: a floor spot with room for the
    whole hand, 1: with room for the fingers, 2: on top of what is there (a second layer)."""
    hu, hv = half_size
    rel = world.yaw_of(obj.body) - yaw
    if not fixed:  # a drawer's turns are all tried by the caller
        delta = fitting_turn(obj.model.extent, rel, delta, (hu, hv))
    held = _half(obj.model.extent, rel + delta)
    e1 = closing_yaw + delta - yaw  # closing axis in the container frame
    along = abs(math.cos(e1)) * held[0] + abs(math.sin(e1)) * held[1]
    closing_gap = max(GAP_CLOSING, finger_reach(world) - along + 0.006)
    gap = np.array(
        [
            abs(math.cos(e1)) * closing_gap + abs(math.sin(e1)) * GAP_ACROSS,
            abs(math.sin(e1)) * closing_gap + abs(math.cos(e1)) * GAP_ACROSS,
        ]
    )
    others = list(fixed)
    for o in world.objects.values():
        if o.id in (obj.id, cont.id) or o.model.fixed or support_of(world, o.id) == ("held", ""):
            continue
        lo, hi = world.body_aabb(o.body)
        local = rot.T @ ((lo[:2] + hi[:2]) / 2 - centre[:2])
        if abs(local[0]) > hu + 0.1 or abs(local[1]) > hv + 0.1 or hi[2] < floor - 0.005:
            continue
        others.append((local, _half(o.model.extent, world.yaw_of(o.body) - yaw), float(hi[2])))
    # the container's own open lid (slid off beside it at rim height) is an obstacle for the hand too
    for part, art in cont.model.articulations.items():
        if art.kind == "lid" and art.is_open(world.joint_position(cont, part)):
            lo, hi = world.aabb(cont.body, cont.links[art.link])
            corners = [
                rot.T @ (np.array([x, y]) - centre[:2]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
            ]
            clo, chi = np.min(corners, axis=0), np.max(corners, axis=0)
            others.append(((clo + chi) / 2, (chi - clo) / 2, float(hi[2])))
    # what stands higher than the hand's underside at release needs the hand's whole footprint clear
    # (22 x 9.4 cm, long along the closing axis), not only the fingers' room
    hand_bottom = floor + obj.model.extent[2] + 0.02
    hand = np.array(
        [
            abs(math.cos(e1)) * HAND_HALF[0] + abs(math.sin(e1)) * HAND_HALF[1],
            abs(math.sin(e1)) * HAND_HALF[0] + abs(math.cos(e1)) * HAND_HALF[1],
        ]
    )
    umax, vmax = hu - held[0] - gap[0], hv - held[1] - gap[1]
    if umax < 0 or vmax < 0:
        umax, vmax = max(umax, 0.0), max(vmax, 0.0)
    grid = [np.array([u, v]) for u in np.linspace(-umax, umax, 13) for v in np.linspace(-vmax, vmax, 13)]
    # corners first: packing from the walls inwards leaves the most room for the next objects
    grid.sort(key=lambda c: -abs(c[0]) - abs(c[1]))

    def tops(c: np.ndarray, hand_room: bool = False) -> list[float]:
        """Tops of what the object would stand on at ``c`` (with ``hand_room``: also of the tall things
        the hand's footprint would meet)."""
        out = []
        for oc, oh, top in others:
            reach = hand if hand_room and top > hand_bottom else held + gap
            if abs(c[0] - oc[0]) < reach[0] + oh[0] and abs(c[1] - oc[1]) < reach[1] + oh[1]:
                out.append(top)
        return out

    # a floor spot with room for the whole hand; else a floor spot with room for the fingers (the hand
    # then stops above the tall neighbour and lets go a little higher); else a second layer
    rank = 0
    free = next((c for c in grid if not tops(c, hand_room=True)), None)
    if free is None:
        rank = 1
        free = next((c for c in grid if not tops(c)), None)
    if free is not None:
        z, best = floor, free
    else:
        rank = 2
        # a second layer only on movable things, never on the cabinet around a drawer
        layer = [c for c in grid if not any(_over(c, held + gap, oc, oh) for oc, oh, _ in fixed)] or grid
        best = min(layer, key=lambda c: (round(max(tops(c)), 3), -abs(c[0]) - abs(c[1])))
        z = max(tops(best)) + 0.003
    xy = centre[:2] + rot @ best
    return np.array([xy[0], xy[1], z]), delta, rank


def _over(c: np.ndarray, reach: np.ndarray, oc: np.ndarray, oh: np.ndarray) -> bool:
    return abs(c[0] - oc[0]) < reach[0] + oh[0] and abs(c[1] - oc[1]) < reach[1] + oh[1]
