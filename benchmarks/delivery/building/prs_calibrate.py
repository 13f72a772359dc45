"""Fitting the PRS station's grid <-> world transforms and schedule-code rooms from observed positions.

PRS's simulator sets each floor's map origin and cell size at run time; the data folder does not state
them. What constrains them: people observed at world positions while their schedule names a room at that
hour (the task files' ``npc_position`` with the person's schedule at the request time). The model is PRS's
own (``x = x0 + i * scale``, ``z = z0 + j * scale``, no rotation); the fit picks the scale and origin that
put the most observations inside the extent of the room their schedule names, one axis at a time (a sweep
over candidate origins for each scale). The schedules' location codes do not all match the room names
(``F3_Bedroom_5`` is not the grid room named ``bed room 5``), so the fit alternates with re-assigning each
code to the grid room where most of its observations fall, then fits again.

This uses only station facts (where a schedule's named room is); it is run on the development task file,
never on the tasks being evaluated.

Floors without observations are *registered* to a fitted floor from the maps alone: PRS's floors share one
navigation-mesh cell size (``accuracy``), and the floors of one building stack, so a floor's origin is the
fitted floor's origin moved by the grid shift that best overlays the two floors' building outlines (the
shift with the highest intersection-over-union of their non-obstacle cells). A floor whose best overlay is
weaker than ``REGISTER_MIN_IOU`` stays uncalibrated, with its best IoU in the summary. A registered floor's
world height is PRS's published floor height (``PRS_FLOOR_HEIGHTS``), which no map file states.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np
from gsr.benchmarks.delivery.building.prs_files import PrsDataError, read_json
from gsr.benchmarks.delivery.building.prs_station import GridTransform, Station, code_floor

#: Fewer observations than this on a floor leave it uncalibrated (a transform from a handful of people
#: would be a guess).
MIN_OBSERVATIONS = 20
#: A floor registers to a fitted floor only when their building outlines overlay at least this well (IoU).
REGISTER_MIN_IOU = 0.75
#: The largest grid shift (cells) tried when registering one floor's outline to another's.
REGISTER_MAX_SHIFT = 40
#: World heights (y, metres) of PRS's floors 0, 1, 2 (F1, F2, F3) as PRS's own map code sets them
#: (``env/map_process.py``, ``RoomMap``); the fitted height of floor 2 agrees (-0.05 m).
PRS_FLOOR_HEIGHTS = {0: -16.693447, 1: -5.2174, 2: -0.0499999}


@dataclass(frozen=True)
class Observation:
    """A person at world ``(x, y, z)`` while their schedule names ``codes`` (the hour's slots)."""

    codes: tuple[str, ...]
    x: float
    y: float
    z: float


def observations_from_tasks(station: Station, path: Path) -> list[Observation]:
    """Person positions of a PRS task file with the schedule codes of each person at the request hour."""
    data = read_json(path)
    if not isinstance(data, dict):
        raise PrsDataError(path, None, "expected an object of tasks keyed by task id")
    out = []
    for tid, task in data.items():
        try:
            person = station.people[int(task["npc_id"])]
            hour = datetime.fromisoformat(task["time"]).hour
            p = task["npc_position"]
            obs = Observation(
                tuple(s.location for s in person.slots_at(hour)), float(p["x"]), float(p["y"]), float(p["z"])
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise PrsDataError(
                path, f"{tid}", f"bad calibration task ({exc.__class__.__name__}: {exc})"
            ) from None
        out.append(obs)
    return out


def _best_origin(u: np.ndarray, lo: np.ndarray, hi: np.ndarray, scale: float) -> tuple[int, float]:
    """Max number of points with ``lo - .5 <= (u - o) / scale <= hi + .5`` over origins ``o``, and the origin."""
    starts = u - scale * (hi + 0.5)
    ends = u - scale * (lo - 0.5)
    events = np.concatenate(
        [np.stack([starts, np.ones_like(starts)], 1), np.stack([ends, -np.ones_like(ends)], 1)]
    )
    order = np.lexsort((-events[:, 1], events[:, 0]))  # at equal positions, openings before closings
    ev = events[order]
    depth = np.cumsum(ev[:, 1])
    k = int(np.argmax(depth))
    # origin: middle of the best interval (until the next event)
    nxt = ev[k + 1, 0] if k + 1 < len(ev) else ev[k, 0]
    return int(depth[k]), float((ev[k, 0] + nxt) / 2)


def fit_transform(
    points: np.ndarray, boxes: np.ndarray, height: float, scales: np.ndarray | None = None
) -> tuple[GridTransform, int]:
    """The transform putting most ``points`` (n x 2 world x, z) in their ``boxes`` (n x 4 i0, i1, j0, j1)."""
    if scales is None:
        scales = np.arange(0.05, 1.0, 0.0025)
    best: tuple[int, int, GridTransform] | None = None
    for s in scales:
        nx, x0 = _best_origin(points[:, 0], boxes[:, 0], boxes[:, 1], float(s))
        nz, z0 = _best_origin(points[:, 1], boxes[:, 2], boxes[:, 3], float(s))
        t = GridTransform(x0, z0, float(s), height)
        score = (_inside(t, points, boxes), nx + nz)
        if best is None or score > best[:2]:
            best = (*score, t)
    assert best is not None
    return best[2], best[0]


def _inside(t: GridTransform, points: np.ndarray, boxes: np.ndarray) -> int:
    """How many points fall (as cells) inside their boxes."""
    i = np.rint((points[:, 0] - t.x0) / t.scale)
    j = np.rint((points[:, 1] - t.z0) / t.scale)
    return int(((i >= boxes[:, 0]) & (i <= boxes[:, 1]) & (j >= boxes[:, 2]) & (j <= boxes[:, 3])).sum())


def _floor_of(obs: Observation) -> int | None:
    levels = {code_floor(c) for c in obs.codes}
    return levels.pop() if len(levels) == 1 else None  # people whose hour spans floors do not calibrate


def calibrate_station(station: Station, observations: list[Observation], rounds: int = 6) -> dict:
    """Fit every observed floor's transform and re-assign schedule codes to rooms; returns a summary
    (also kept in ``station.calibration``). Floors without observations keep no transform."""
    by_floor: dict[int, list[Observation]] = defaultdict(list)
    for o in observations:
        level = _floor_of(o)
        if level is not None and level in station.floors:
            by_floor[level].append(o)
    summary: dict = {"observations": len(observations), "floors": {}}
    for level, obs in sorted(by_floor.items()):
        if len(obs) < MIN_OBSERVATIONS:
            continue
        height = float(np.median([o.y for o in obs]))
        floor = station.floors[level]
        reassigned: dict[str, str] = {}
        for _ in range(rounds):
            pts, boxes, used = [], [], []
            for o in obs:
                rooms = {station.location_rooms.get(c) for c in o.codes if code_floor(c) == level}
                rooms.discard(None)
                if len(rooms) == 1:
                    r = station.room(rooms.pop())
                    pts.append((o.x, o.z))
                    boxes.append(r.box)
                    used.append(o)
            if len(pts) < 3:
                break
            t, _ = fit_transform(np.asarray(pts, float), np.asarray(boxes, float), height)
            floor.transform = t
            # re-assign codes: the grid room where most of a code's single-code observations fall
            votes: dict[str, Counter] = defaultdict(Counter)
            for o in obs:
                codes = [c for c in o.codes if code_floor(c) == level]
                if len(set(codes)) == 1:
                    room = station.room_at(level, t.to_cell(o.x, o.z))
                    votes[codes[0]][room.id if room else None] += 1
            changed = False
            for code, v in votes.items():
                v.pop(None, None)
                if not v:
                    continue
                room_id, n = v.most_common(1)[0]
                if room_id is not None and n >= 2 and station.location_rooms.get(code) != room_id:
                    station.location_rooms[code] = room_id
                    reassigned[code] = room_id
                    changed = True
            if not changed:
                break
        if floor.transform is not None:
            summary["floors"][level] = {
                "x0": floor.transform.x0,
                "z0": floor.transform.z0,
                "scale": floor.transform.scale,
                "height": height,
                "observations": len(obs),
                "reassigned_codes": dict(sorted(reassigned.items())),
            }
    register_floors(station, summary)
    station.calibration = summary
    return summary


def register_shift(
    mask: np.ndarray, ref: np.ndarray, max_shift: int = REGISTER_MAX_SHIFT
) -> tuple[int, int, float]:
    """``(di, dj, iou)``: the shift putting cell ``(i, j)`` of ``mask`` on ``(i + di, j + dj)`` of ``ref``
    with the highest intersection-over-union of their true cells."""
    total = int(mask.sum()) + int(ref.sum())
    best = (0, 0, -1.0)
    for di in range(-max_shift, max_shift + 1):
        i0, i1 = max(0, -di), min(mask.shape[0], ref.shape[0] - di)
        if i1 <= i0:
            continue
        for dj in range(-max_shift, max_shift + 1):
            j0, j1 = max(0, -dj), min(mask.shape[1], ref.shape[1] - dj)
            if j1 <= j0:
                continue
            inter = int(np.count_nonzero(mask[i0:i1, j0:j1] & ref[i0 + di : i1 + di, j0 + dj : j1 + dj]))
            iou = inter / max(1, total - inter)
            if iou > best[2]:
                best = (di, dj, iou)
    return best


def register_floors(station: Station, summary: dict) -> None:
    """Give each floor without a transform the transform of the fitted floor whose outline overlays it
    best (``register_shift``), when the overlay reaches ``REGISTER_MIN_IOU``; the summary says either way."""
    fitted = {lvl: f for lvl, f in station.floors.items() if f.transform is not None}
    summary.setdefault("registered", {})
    for level, floor in sorted(station.floors.items()):
        if floor.transform is not None or not fitted:
            continue
        mask = floor.grid != 0
        best = None
        for ref_level, ref in fitted.items():
            di, dj, iou = register_shift(mask, ref.grid != 0)
            if best is None or iou > best[3]:
                best = (ref_level, di, dj, iou)
        assert best is not None
        ref_level, di, dj, iou = best
        entry = {"reference_floor": ref_level, "shift": [di, dj], "iou": round(iou, 3)}
        if iou >= REGISTER_MIN_IOU and level in PRS_FLOOR_HEIGHTS:
            t = fitted[ref_level].transform
            assert t is not None
            floor.transform = GridTransform(
                t.x0 + di * t.scale, t.z0 + dj * t.scale, t.scale, PRS_FLOOR_HEIGHTS[level]
            )
            entry.update(x0=floor.transform.x0, z0=floor.transform.z0, height=floor.transform.height)
        else:
            entry["uncalibrated"] = f"outline overlay IoU {iou:.2f} < {REGISTER_MIN_IOU}"
        summary["registered"][level] = entry


def schedule_agreement(station: Station, observations: list[Observation]) -> tuple[int, int]:
    """``(in_room, total)``: observations whose position lies in a room one of the hour's slots names."""
    hits = 0
    for o in observations:
        where = station.locate(o.x, o.y, o.z)
        rooms = {station.location_rooms.get(c) for c in o.codes}
        if where is not None:
            room = station.room_at(*where)
            hits += room is not None and room.id in rooms
    return hits, len(observations)
