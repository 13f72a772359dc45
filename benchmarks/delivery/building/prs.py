"""Reading a PRS data folder into a ``Station`` (``gsr.benchmarks.delivery.building.prs_station``).

``load_station(folder)`` reads (through ``gsr.benchmarks.delivery.building.prs_files``):

- each floor's semantic grid, the room of every cell (room tags of the grid, else the room extents of
  ``map_room_data.json``) and which cells a robot may stand on (accessible or room floor, not furniture);
- rooms with their human names (``room_mapping.json``), receptacles with grid extents (``map_receptacle_data``);
- people (description template, appearance, information) and their 24 hourly schedule slots;
- per floor, the grid <-> world transform, which the data does not state: ``gsr.benchmarks.delivery.building.prs_calibrate``
  fits it (with the schedules' location codes -> grid rooms) from observed person positions.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from gsr.benchmarks.delivery.building.prs_calibrate import calibrate_station, observations_from_tasks
from gsr.benchmarks.delivery.building.prs_files import (
    PrsDataError,
    check_folder,
    floor_levels,
    int_range,
    need,
    read_grid,
    read_json,
)
from gsr.benchmarks.delivery.building.prs_station import (
    Floor,
    Person,
    Receptacle,
    Room,
    Slot,
    Station,
    code_floor,
    location_key,
)


def _tags(path: Path, data: object, level: int) -> dict[int, tuple[str | None, str | None]]:
    """Grid value -> (room key, receptacle name) from ``semantic_map_tags.json``."""
    table = need(data, str(level), dict, path, f"floor {level}")
    out: dict[int, tuple[str | None, str | None]] = {}
    for value, tag in table.items():
        if not value.isdigit():
            raise PrsDataError(path, f"floor {level} -> {value!r}", "grid values must be integers")
        if isinstance(tag, str):
            out[int(value)] = (None, None)  # 'obstacles', 'accessible area'
        elif isinstance(tag, list) and 1 <= len(tag) <= 2 and all(isinstance(t, str) for t in tag):
            out[int(value)] = (tag[0], tag[1] if len(tag) == 2 else None)
        else:
            raise PrsDataError(
                path, f"floor {level} -> {value}", "expected a name or [room] / [room, receptacle]"
            )
    return out


def load_station(folder: str | Path, calibrate_with: str | Path | None = "auto") -> Station:
    """Read a PRS data folder into a ``Station``; errors name the file and field.

    ``calibrate_with``: a PRS task file whose person positions fit each floor's transform and the schedule
    codes' rooms (``"auto"``: the folder's ``delivery_tasks_dev.json`` when present; ``None``: no
    calibration, transforms stay unknown).
    """
    folder = Path(folder)
    check_folder(folder)
    names_path, rooms_path = folder / "room_mapping.json", folder / "map_room_data.json"
    tags_path, rec_path = folder / "semantic_map_tags.json", folder / "map_receptacle_data.json"
    names, extents = read_json(names_path), read_json(rooms_path)
    tags, rec_data = read_json(tags_path), read_json(rec_path)
    rooms: list[Room] = []
    receptacles: list[Receptacle] = []
    floors: dict[int, Floor] = {}
    for level in floor_levels(folder):
        grid = read_grid(folder / f"semantic_map_{level}.txt")
        floor_names = need(names, str(level), dict, names_path, f"floor {level}")
        floor_ext = need(extents, str(level), dict, rooms_path, f"floor {level}")
        index: dict[str, int] = {}
        for key, ext in floor_ext.items():
            name = need(floor_names, key, str, names_path, f"floor {level} -> {key}")
            box = int_range(
                need(ext, "x", list, rooms_path, f"{level} -> {key} -> x"), rooms_path, f"{level}.{key}.x"
            )
            box += int_range(
                need(ext, "y", list, rooms_path, f"{level} -> {key} -> y"), rooms_path, f"{level}.{key}.y"
            )
            index[key] = len(rooms)
            rooms.append(Room(f"F{level}.{key}", level, key, name, box))
        tag = _tags(tags_path, tags, level)
        for key in {k for k, _ in tag.values() if k is not None} - set(index):
            raise PrsDataError(tags_path, f"floor {level}", f"unknown room {key!r}")
        floor_rooms = [(k, r) for k, r in enumerate(rooms) if r.floor == level]
        offset = _tag_offset(grid, tag, floor_rooms, index)
        room_of = np.full(grid.shape, -1, dtype=np.int32)
        walkable = grid == 1
        blocked = np.zeros(grid.shape, dtype=bool)
        receptacle_of = np.full(grid.shape, -1, dtype=np.int32)
        for value in np.unique(grid):
            room_key, rec_name = tag.get(int(value) + offset, (None, None)) if value > 1 else (None, None)
            cells = grid == value
            if room_key is not None:
                room_of[cells] = index[room_key]
                walkable |= cells if rec_name is None else False
            if rec_name is not None or (value > 1 and room_key is None):
                blocked |= cells  # furniture, or a value the tags do not explain
            if rec_name is not None:
                for comp in _components(cells):
                    i0, j0 = comp.min(0)
                    i1, j1 = comp.max(0)
                    receptacle_of[comp[:, 0], comp[:, 1]] = len(receptacles)
                    centre = (int(i0 + i1) // 2, int(j0 + j1) // 2)
                    receptacles.append(
                        Receptacle(
                            f"F{level}.rec{len(receptacles)}", level, "", rec_name, (i0, i1, j0, j1), centre
                        )
                    )
        for k, r in floor_rooms:  # the rooms' extents decide; tags fill cells outside every extent
            i0, i1, j0, j1 = r.box
            room_of[i0 : i1 + 1, j0 : j1 + 1] = k
        for n, rec in enumerate(receptacles):
            if rec.floor == level:
                k = int(room_of[rec.centre])
                receptacles[n] = replace(rec, room=rooms[k].id if k >= 0 else "")
        _check_receptacle_file(rec_path, rec_data, level, index)
        floors[level] = Floor(level, grid, room_of, receptacle_of, walkable & ~blocked, tag_offset=offset)
    station = Station(folder, floors, rooms, receptacles, _people(folder))
    station.location_rooms = default_location_rooms(station)
    if calibrate_with == "auto":
        dev = folder / "delivery_tasks_dev.json"
        calibrate_with = dev if dev.is_file() else None
    if calibrate_with is not None:
        calibrate_station(station, observations_from_tasks(station, Path(calibrate_with)))
    return station


def _components(mask: np.ndarray) -> list[np.ndarray]:
    """The 8-connected components of a boolean mask, each as an (n, 2) array of cells."""
    from scipy import ndimage

    labels, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=int))
    return [np.argwhere(labels == k) for k in range(1, n + 1)]


def _tag_offset(
    grid: np.ndarray, tag: dict, floor_rooms: list[tuple[int, Room]], index: dict[str, int]
) -> int:
    """The shift between grid values and tag keys (value ``v`` is tag ``v + offset``) that best agrees with
    the rooms' extents: PRS's published grids are one value below their tags."""
    scores: list[tuple[int, int, int]] = []
    for offset in (0, 1, -1):
        hits = 0
        for value in np.unique(grid):
            room_key = tag.get(int(value) + offset, (None, None))[0] if value > 1 else None
            if room_key is None:
                continue
            i0, i1, j0, j1 = next(r.box for k, r in floor_rooms if k == index[room_key])
            cells = np.argwhere(grid == value)
            inside = (cells[:, 0] >= i0) & (cells[:, 0] <= i1) & (cells[:, 1] >= j0) & (cells[:, 1] <= j1)
            hits += int(inside.sum())
        scores.append((hits, -abs(offset), offset))
    return max(scores)[2]


def _check_receptacle_file(path: Path, data: object, level: int, index: dict[str, int]) -> None:
    """Validate ``map_receptacle_data.json`` for a floor (its room keys do not match the grid on every floor,
    so receptacles come from the grid; the file must still be well formed)."""
    if not isinstance(data, dict):
        raise PrsDataError(path, None, "expected an object of floors")
    floor_rec = data.get(str(level), {})
    if not isinstance(floor_rec, dict):
        raise PrsDataError(path, f"floor {level}", "expected an object of rooms")
    for room_key, entry in floor_rec.items():
        items = need(entry, "receptacles", list, path, f"floor {level} -> {room_key} -> receptacles")
        for n, rec in enumerate(items):
            where = f"floor {level} -> {room_key} -> receptacles[{n}]"
            need(rec, "name", str, path, f"{where} -> name")
            int_range(need(rec, "x", list, path, f"{where} -> x"), path, f"{where} -> x")
            int_range(need(rec, "y", list, path, f"{where} -> y"), path, f"{where} -> y")


def default_location_rooms(station: Station) -> dict[str, str]:
    """Schedule location codes -> room ids by name (``F3_KitchenRoom`` -> the ``kitchen room`` of floor 2)."""
    by_key = {(r.floor, location_key(r.name)): r.id for r in station.rooms}
    out: dict[str, str] = {}
    for person in station.people.values():
        for slots in person.schedule.values():
            for s in slots:
                level = code_floor(s.location)
                rid = by_key.get((level, location_key(s.location.split("_", 1)[-1])))
                if rid is not None:
                    out[s.location] = rid
    return out


def _people(folder: Path) -> dict[int, Person]:
    data_path, sched_path = folder / "npc_data.json", folder / "npc_schedule.json"
    data, sched = read_json(data_path), read_json(sched_path)
    people = need(data, "npc", list, data_path, "npc")
    out: dict[int, Person] = {}
    for n, p in enumerate(people):
        where = f"npc[{n}]"
        info = need(p, "information", dict, data_path, f"{where} -> information")
        pid = need(info, "id", int, data_path, f"{where} -> information -> id")
        entry = need(sched, str(pid), dict, sched_path, str(pid))
        hours = need(entry, "schedule", dict, sched_path, f"{pid} -> schedule")
        schedule: dict[int, tuple[Slot, ...]] = {}
        for hour, slots in hours.items():
            if not hour.isdigit() or not isinstance(slots, list):
                raise PrsDataError(
                    sched_path, f"{pid} -> schedule -> {hour}", "expected an hour 0-23 and a list"
                )
            parsed = []
            for k, s in enumerate(slots):
                f = f"{pid} -> schedule -> {hour}[{k}]"
                loc = need(s, "location", str, sched_path, f"{f} -> location")
                acts = s.get("action", []) if isinstance(s, dict) else []
                parsed.append(Slot(loc, tuple(a for a in acts if isinstance(a, str))))
            schedule[int(hour)] = tuple(parsed)
        out[pid] = Person(
            pid,
            need(p, "description", str, data_path, f"{where} -> description"),
            need(p, "feature", str, data_path, f"{where} -> feature"),
            need(p, "character", str, data_path, f"{where} -> character").strip(),
            info,
            schedule,
        )
    return out
