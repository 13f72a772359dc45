"""Where a held object can stand on a fixture's top: level, fully supported, clear of what is there.

A fixture's bounding box is not its working surface: a stove's knob sticks up above its burner plate,
a rack has rails, a second moka pot already stands on the stove. :func:`surface_spot` probes the
surface with vertical rays at the object's footprint (its centre, corners and edge midpoints, widened
by a margin for the fingers): a spot counts only when every ray meets the target itself at the same
height (level and supported under the whole footprint, nothing else standing there). The height the
rays meet is where the object's bottom goes, so nothing is dropped from the top of a knob.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from gsr.skills.packing import HAND_HALF
from gsr.skills.world import SimObject, World

#: Room kept free around the held object's footprint (m): the opening fingers and a little play.
MARGIN = 0.012
#: Rays meeting the surface at heights this far apart (m) mean it is not level there (a burner plate
#: 6 mm proud of a stove still carries a pan; a knob or a rack's rail does not).
LEVEL = 0.008


def _probe_points(c: np.ndarray, half: np.ndarray) -> np.ndarray:
    """The centre, corners and edge midpoints of the footprint ``half`` around ``c`` (x, y)."""
    offsets = [(i, j) for i in (-1.0, 0.0, 1.0) for j in (-1.0, 0.0, 1.0)]
    return np.array([c + half * np.array(o) for o in offsets])


def _closing_axis(world: World) -> np.ndarray:
    """The fingers' closing axis on the table (unit x, y) as the hand holds the object now."""
    import pybullet as p

    rot = np.array(p.getMatrixFromQuaternion(list(world.robot.ee_pose()[1]))).reshape(3, 3)
    e1 = rot[:2, 1]
    return e1 / max(float(np.linalg.norm(e1)), 1e-9)


def _tall_neighbours(world: World, obj: SimObject, hand_bottom: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """(centre, half size) of the movable objects whose top reaches the hand's underside at release."""
    out = []
    for o in world.objects.values():
        if o.id == obj.id or o.model.fixed:
            continue
        nlo, nhi = world.body_aabb(o.body)
        if nhi[2] > hand_bottom + 0.02:
            out.append(((nlo[:2] + nhi[:2]) / 2, (nhi[:2] - nlo[:2]) / 2))
    return out


def _hand_meets(c: np.ndarray, e1: np.ndarray, nc: np.ndarray, nh: np.ndarray) -> bool:
    """Whether the hand's footprint (22 x 9.4 cm, long along ``e1``) centred at ``c`` meets a box."""
    e2 = np.array([-e1[1], e1[0]])
    d = nc - c
    for axis, h in ((e1, HAND_HALF[0]), (e2, HAND_HALF[1])):
        if abs(float(d @ axis)) >= h + abs(axis[0]) * nh[0] + abs(axis[1]) * nh[1]:
            return False
    return not (
        abs(d[0]) >= nh[0] + abs(e1[0]) * HAND_HALF[0] + abs(e2[0]) * HAND_HALF[1]
        or abs(d[1]) >= nh[1] + abs(e1[1]) * HAND_HALF[0] + abs(e2[1]) * HAND_HALF[1]
    )


def hand_crowding(world: World, obj: SimObject, z: float, turn: float = 0.0) -> Callable[[np.ndarray], bool]:
    """Whether the hand, setting the held ``obj`` down with its bottom at height ``z`` at a point (x, y),
    would meet a neighbour standing taller than the hand's underside (the hand's footprint is 22 x 9.4
    cm, long along the closing axis, as the object is held now and the wrist then turned by ``turn``)."""
    olo, ohi = world.body_aabb(obj.body)
    tall = _tall_neighbours(world, obj, z + float(ohi[2] - olo[2]))
    c, s = np.cos(turn), np.sin(turn)
    e1 = np.array([[c, -s], [s, c]]) @ _closing_axis(world)

    def crowded(c: np.ndarray) -> bool:
        return any(_hand_meets(np.asarray(c[:2]), e1, nc, nh) for nc, nh in tall)

    return crowded


#: Room kept between a placed object's footprint and a handle or knob of the fixture it stands on (m).
HANDLE_ROOM = 0.06


def _handles(world: World, body: int) -> list[np.ndarray]:
    """Where the handles and knobs of the object whose body is ``body`` are (x, y)."""
    host = next((o for o in world.objects.values() if o.body == body), None)
    if host is None:
        return []
    out = []
    for art in host.model.articulations.values():
        if art.handle is not None and art.handle.link in host.links:
            out.append(world.to_world(body, host.links[art.handle.link], art.handle.xyz)[:2])
    return out


def surface_spot(
    world: World,
    obj: SimObject,
    body: int,
    lo: np.ndarray,
    hi: np.ndarray,
    links: set[int] | None = None,
    prefer_near: bool = True,
) -> np.ndarray | None:
    """A point (x, y, surface height) on ``body`` within ``lo..hi`` where the held ``obj`` stands level.

    ``links`` limits the surface to some links of the body (a part such as a cabinet's top side);
    ``None`` accepts any. ``prefer_near``: of the good spots, the one nearest the robot's side (-x),
    then nearest the middle; else the one nearest the middle. None when no spot passes.
    """
    import pybullet as p

    olo, ohi = world.body_aabb(obj.body)
    half = (ohi[:2] - olo[:2]) / 2 + MARGIN
    xlo, xhi = lo[0] + half[0] - MARGIN, hi[0] - half[0] + MARGIN
    ylo, yhi = lo[1] + half[1] - MARGIN, hi[1] - half[1] + MARGIN
    if xlo > xhi or ylo > yhi:
        return None
    xs = np.linspace(xlo, xhi, 9) if xhi - xlo > 1e-6 else np.array([xlo])
    ys = np.linspace(ylo, yhi, 9) if yhi - ylo > 1e-6 else np.array([ylo])
    candidates = [np.array([x, y]) for x in xs for y in ys]
    top = float(hi[2]) + 0.005
    bottom = float(lo[2]) - 0.01
    starts, ends = [], []
    for c in candidates:
        for q in _probe_points(c, half):
            starts.append((q[0], q[1], top))
            ends.append((q[0], q[1], bottom))
    hits = []
    batch = 1000  # rayTestBatch caps the number of rays per call
    for i in range(0, len(starts), batch):
        hits += p.rayTestBatch(starts[i : i + batch], ends[i : i + batch], physicsClientId=world.client)
    n = len(_probe_points(np.zeros(2), half))
    middle = np.array([(xlo + xhi) / 2, (ylo + yhi) / 2])
    crowded_at = hand_crowding(world, obj, float(lo[2]))
    # the fixture's own handles and knobs stay free for the hand (a pan set down beside the stove's
    # knob blocks turning it on)
    handles = _handles(world, body)
    reach = float(np.max(half)) + HANDLE_ROOM
    good: list[tuple[tuple[int, int, float, float], np.ndarray, float]] = []
    for k, c in enumerate(candidates):
        rays = hits[k * n : (k + 1) * n]
        if any(r[0] != body or (links is not None and r[1] not in links) for r in rays):
            continue  # off the edge, onto another body, or onto a part that is not the surface
        zs = [float(r[3][2]) for r in rays]
        if max(zs) - min(zs) > LEVEL:
            continue  # not level under the footprint: a knob, a rail, an edge
        # the hand's whole footprint clear of tall neighbours first (a second moka pot beside the first)
        crowded = (int(crowded_at(c)), int(any(float(np.linalg.norm(c - h)) < reach for h in handles)))
        key = (
            (*crowded, round(float(c[0]), 4), round(abs(float(c[1] - middle[1])), 4))
            if prefer_near
            else (*crowded, round(float(np.linalg.norm(c - middle)), 4), 0.0)
        )
        good.append((key, c, max(zs)))
    if not good:
        return None
    _, c, z = min(good, key=lambda g: g[0])
    return np.array([c[0], c[1], z])


def uncrowded_turn(world: World, obj: SimObject, spot: np.ndarray) -> float:
    """0, or the quarter turn of the wrist that keeps the hand off the tall neighbours at ``spot`` when
    the hand as it is would meet one (and the turned hand does not)."""
    if not hand_crowding(world, obj, float(spot[2]))(spot):
        return 0.0
    for turn in (np.pi / 2, -np.pi / 2):
        if not hand_crowding(world, obj, float(spot[2]), turn)(spot):
            return float(turn)
    return 0.0
