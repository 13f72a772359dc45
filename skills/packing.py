"""Where to put an object into a container so that several fit: spots in the container's own frame.

A box may stand at any yaw and so may the cubes going into it. Reasoning with world-aligned boxes
wastes most of the floor, so the spot is chosen in the container's frame, with the held object turned
(the wrist rotates by ``delta``, at most 45 degrees, or up to 135 when only the other way round fits)
to line up with the container's walls. Along the fingers' closing axis the fingers need their
measured reach beside the object; across it half a centimetre.
When the floor is full the object goes on the lowest neighbour: a second layer.
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


def _container(world: World, target: str) -> tuple[SimObject, Interior, int] | None:
    """The object and interior behind a container node (objects and their compartments; not drawers)."""
    if target in world.objects:
        o = world.objects[target]
        interior = o.model.interiors.get("")
    elif target in world.parts:
        obj_id, part = world.parts[target]
        o = world.objects[obj_id]
        if part in o.model.articulations:  # drawers: handled with their exposed area
            return None
        interior = o.model.interiors.get(part)
    else:
        return None
    return (o, interior, o.links[interior.link]) if interior is not None else None


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
    cont, interior, link = found
    yaw = world.yaw_of(cont.body, link)
    centre = world.to_world(cont.body, link, interior.center)
    hu, hv = interior.size[0] / 2, interior.size[1] / 2
    floor = centre[2] - interior.size[2] / 2
    # turn the held object (by the wrist) so its sides run along the container's walls
    rel = world.yaw_of(obj.body) - yaw
    delta = -(((rel + math.pi / 4) % (math.pi / 2)) - math.pi / 4)
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
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    others = []
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
    grid = [np.array([u, v]) for u in np.linspace(-umax, umax, 9) for v in np.linspace(-vmax, vmax, 9)]
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
    free = next((c for c in grid if not tops(c, hand_room=True)), None)
    free = free if free is not None else next((c for c in grid if not tops(c)), None)
    if free is not None:
        z, best = floor, free
    else:
        best = min(grid, key=lambda c: (round(max(tops(c)), 3), -abs(c[0]) - abs(c[1])))
        z = max(tops(best)) + 0.003
    xy = centre[:2] + rot @ best
    return np.array([xy[0], xy[1], z]), delta
