"""Where a layout's objects start inside a box: side by side across it, in rows round its middle.

GSR-Bench's boxes are 8.5 cm deep. Over a 3 cm cube on the floor the Panda's hand (20 cm along its
closing axis) is below the wall tops, so a later pick must put the whole hand *inside* the box, lying
along its long side near its middle, the fingers closing along that side
(:mod:`gsr.skills.hand_clearance`). A cube that starts 7 cm from the middle along the long side (the
old 3 x 3 grid's second slot) fits no such hand, with or without a neighbour; two cubes side by side
*across* the box fit one each, because the fingers then close on their faces along the long side,
away from the neighbour. So the objects a layout puts in one box fill a row across the short side
first (a small gap apart), centred; further rows go along the long side, far enough apart for a finger
between them, all centred on the box's middle. ``None`` when they do not fit on the floor (the caller
keeps its own grid). Only for boxes whose contents are all that low (:data:`HAND_OVER_TOP`): measured
on the 38 generated scenes with two or more objects in one box, the rows across put a cube beside a mug
where the hand lying across met the mug.
"""

from __future__ import annotations

import math

import numpy as np

#: Gap (m) between neighbours in a row across the box (the fingers close along the long side: no
#: finger goes between them) and between rows along it (a finger, 2.6 cm deep, and its opening).
GAP_ACROSS, GAP_ALONG = 0.012, 0.04
#: How far (m) above an object's top the hand's underside is when the fingers grip its upper 1.5 cm
#: (:mod:`gsr.skills.hand_clearance`: underside 3.9 cm above the grasp point, fingertips 0.7 cm below
#: it). Only objects whose top plus this stays below the rim need the hand inside the box; the slots
#: are for boxes holding only such objects (a mug, 5.4 cm tall in an 8.5 cm box, is gripped from above
#: the walls and keeps the layout's own grid).
HAND_OVER_TOP = 0.031
#: ... and stays at least this far (m) below the rim: a hand only that low is surely inside the box (a
#: 5 cm mug's hand, 0.4 cm from a 8.5 cm box's rim, tilts over the wall instead).
INSIDE_MARGIN = 0.01
#: Room (m) kept between an object and the box's walls.
WALL_ROOM = 0.005


def turned_footprint(centre: np.ndarray, half: np.ndarray, rel_yaw: float) -> tuple[np.ndarray, np.ndarray]:
    """An object's footprint ``(centre offset from its origin, half sizes)`` in a frame turned by
    ``-rel_yaw`` from the object's own (the object stands at ``rel_yaw`` in it): the centre offset
    rotated, the half sizes of the axis-aligned box round the turned rectangle."""
    c, s = math.cos(rel_yaw), math.sin(rel_yaw)
    rot = np.array([[c, -s], [s, c]])
    return rot @ np.asarray(centre, dtype=float), np.abs(rot) @ np.asarray(half, dtype=float)


def box_slots(halves: list[np.ndarray], room: np.ndarray) -> list[np.ndarray] | None:
    """Footprint centres (in the interior's frame, from its middle) for objects with footprint half
    sizes ``halves`` (in that frame, in loading order) on a floor of half size ``room``: rows across
    the short axis, filled in order, centred; rows along the long axis, centred. None if they do not fit."""
    room = np.asarray(room, dtype=float)
    long_k = int(np.argmax(room))
    short_k = 1 - long_k
    width = 2 * (room[short_k] - WALL_ROOM)
    rows: list[list[int]] = [[]]
    used = 0.0
    for i, h in enumerate(halves):
        w = 2 * float(h[short_k])
        if w > width:
            return None
        need = used + (GAP_ACROSS if rows[-1] else 0.0) + w
        if rows[-1] and need > width:
            rows.append([])
            need = w
        rows[-1].append(i)
        used = need
    depths = [2 * max(float(halves[i][long_k]) for i in row) for row in rows]
    length = sum(depths) + GAP_ALONG * (len(rows) - 1)
    if length > 2 * (room[long_k] - WALL_ROOM):
        return None
    out: list[np.ndarray | None] = [None] * len(halves)
    along = -length / 2
    for row, depth in zip(rows, depths, strict=True):
        widths = [2 * float(halves[i][short_k]) for i in row]
        across = -(sum(widths) + GAP_ACROSS * (len(row) - 1)) / 2
        for i, w in zip(row, widths, strict=True):
            uv = np.zeros(2)
            uv[long_k] = along + depth / 2
            uv[short_k] = across + w / 2
            out[i] = uv
            across += w + GAP_ACROSS
        along += depth + GAP_ALONG
    return [uv for uv in out if uv is not None]
