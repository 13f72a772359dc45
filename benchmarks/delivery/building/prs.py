"""The PRS research station as a building model: floors, rooms, receptacles, free space, people, schedules.

``load_station(folder)`` reads a PRS data folder (``gsr.benchmarks.delivery.building.prs_files``) into a ``Station``:

- each floor's semantic grid, the room of every cell (room tags of the grid, else the room extents of
  ``map_room_data.json``) and which cells a robot may stand on (accessible or room floor, not furniture);
- rooms with their human names (``room_mapping.json``), receptacles with grid extents (``map_receptacle_data``);
- people (description template, appearance, information) and their 24 hourly schedule slots;
- per floor, the grid <-> world transform, which the data does not state: ``gsr.benchmarks.delivery.building.prs_calibrate``
  fits it (with the schedules' location codes -> grid rooms) from observed person positions;
- ``place_object``: an object of the inventory (the objects a task file names) at its world position, with
  the floor, cell, room and receptacle it lies on, derived from that geometry.

Grid coordinates are ``(i, j)`` = (row, column) of the semantic map; PRS's world frame has ``x`` along ``i``
and ``z`` along ``j`` (``x = x0 + i * scale``, ``z = z0 + j * scale``), ``y`` up.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from gsr.benchmarks.delivery.building.prs_files import (
    PrsDataError,
    check_folder,
    floor_levels,
    int_range,
    need,
    read_grid,
    read_json,
)

Cell = tuple[int, int]
#: A point more than this far below the lowest calibrated floor is on no calibrated floor (metres).
STOREY_M = 3.0


@dataclass(frozen=True)
class GridTransform:
    """``x = x0 + i * scale``, ``z = z0 + j * scale``; ``height`` is the floor's world ``y``."""

    x0: float
    z0: float
    scale: float
    height: float = 0.0

    def to_cell(self, x: float, z: float) -> Cell:
        """The grid cell whose centre is nearest to world ``(x, z)``."""
        return (round((x - self.x0) / self.scale), round((z - self.z0) / self.scale))

    def to_world(self, i: float, j: float) -> tuple[float, float]:
        """World ``(x, z)`` of grid coordinates ``(i, j)``."""
        return (self.x0 + i * self.scale, self.z0 + j * self.scale)


@dataclass(frozen=True)
class Room:
    """A room: ``id`` like ``F2.room7``, human ``name`` (``kitchen room``), inclusive grid extent."""

    id: str
    floor: int
    key: str
    name: str
    box: tuple[int, int, int, int]  # i_min, i_max, j_min, j_max (inclusive)

    def contains(self, cell: Cell) -> bool:
        """True when ``cell`` lies in the room's extent."""
        i, j = cell
        return self.box[0] <= i <= self.box[1] and self.box[2] <= j <= self.box[3]


@dataclass(frozen=True)
class Receptacle:
    """Furniture objects rest on: ``name`` (``kitchen counter``), room, inclusive grid extent, centre."""

    id: str
    floor: int
    room: str
    name: str
    box: tuple[int, int, int, int]
    centre: Cell


@dataclass(frozen=True)
class Slot:
    """Where a person is during part of an hour: a PRS location code and the actions there."""

    location: str
    actions: tuple[str, ...]


@dataclass(frozen=True)
class Person:
    """A PRS person: description template (``{name}``), appearance, information, hourly schedule."""

    id: int
    description: str
    feature: str
    character: str
    information: dict
    schedule: dict[int, tuple[Slot, ...]]

    def slots_at(self, hour: int) -> tuple[Slot, ...]:
        """The schedule's slots for an hour of the day (0-23)."""
        return self.schedule.get(hour % 24, ())

    def describe(self, name: str) -> str:
        """The description as PRS hands it to the robot: the template with the person's name."""
        return self.description.replace("{name}", name)


@dataclass
class Floor:
    """A floor: semantic grid, room index per cell (-1 none), receptacle index per cell, walkable mask."""

    level: int
    grid: np.ndarray
    room_of: np.ndarray
    receptacle_of: np.ndarray
    walkable: np.ndarray
    transform: GridTransform | None = None
    tag_offset: int = 0

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)``."""
        return (int(self.grid.shape[0]), int(self.grid.shape[1]))

    def inside(self, cell: Cell) -> bool:
        """True when ``cell`` is on the grid."""
        return 0 <= cell[0] < self.grid.shape[0] and 0 <= cell[1] < self.grid.shape[1]


@dataclass
class Station:
    """The whole PRS station: floors, rooms, receptacles, people; location codes -> rooms."""

    folder: Path
    floors: dict[int, Floor]
    rooms: list[Room]
    receptacles: list[Receptacle]
    people: dict[int, Person]
    location_rooms: dict[str, str] = field(default_factory=dict)
    calibration: dict = field(default_factory=dict)

    def room(self, room_id: str) -> Room:
        """The room with id ``room_id``."""
        return self._rooms_by_id[room_id]

    def __post_init__(self) -> None:
        self._rooms_by_id = {r.id: r for r in self.rooms}

    def room_at(self, floor: int, cell: Cell) -> Room | None:
        """The room containing a cell (``None`` in corridors or off the grid)."""
        f = self.floors.get(floor)
        if f is None or not f.inside(cell):
            return None
        k = int(f.room_of[cell])
        return self.rooms[k] if k >= 0 else None

    def receptacles_in(self, room_id: str) -> list[Receptacle]:
        """The receptacles of a room."""
        return [r for r in self.receptacles if r.room == room_id]

    def room_of_location(self, code: str) -> Room | None:
        """The room a schedule location code (``F3_KitchenRoom``) names, if the station knows it."""
        rid = self.location_rooms.get(code)
        return self._rooms_by_id.get(rid) if rid else None

    def floor_of_height(self, y: float) -> int | None:
        """The calibrated floor a world height belongs to (the highest floor not above ``y`` + 0.5 m);
        ``None`` more than ``STOREY_M`` below the lowest calibrated floor (an uncalibrated floor under it)."""
        known = [(f.transform.height, lvl) for lvl, f in self.floors.items() if f.transform is not None]
        below = [(h, lvl) for h, lvl in known if h <= y + 0.5]
        if below:
            return max(below)[1]
        return min(known)[1] if known and y > min(known)[0] - STOREY_M else None

    def locate(self, x: float, y: float, z: float) -> tuple[int, Cell] | None:
        """``(floor, cell)`` of a world point, or ``None`` when no floor is calibrated for it."""
        level = self.floor_of_height(y)
        if level is None:
            return None
        t = self.floors[level].transform
        assert t is not None
        return level, t.to_cell(x, z)


@dataclass(frozen=True)
class PlacedObject:
    """An inventory object: simulator name, detector type, world position, and where it lies."""

    name: str
    type: str
    position: tuple[float, float, float]
    floor: int | None
    cell: tuple[int, int] | None
    room: str | None
    receptacle: str | None


def place_object(
    station: Station, name: str, type_: str, position: tuple[float, float, float]
) -> PlacedObject:
    """An object at a world position with its floor, cell, room and the receptacle it rests on (the
    receptacle whose footprint is nearest the object's cell, within two cells)."""
    where = station.locate(*position)
    if where is None:
        return PlacedObject(name, type_, position, None, None, None, None)
    level, cell = where
    room = station.room_at(level, cell)
    best: tuple[int, str] | None = None
    for rec in station.receptacles:
        if rec.floor != level:
            continue
        i0, i1, j0, j1 = rec.box
        d = max(i0 - cell[0], cell[0] - i1, 0) + max(j0 - cell[1], cell[1] - j1, 0)
        if d <= 2 and (best is None or d < best[0]):
            best = (d, rec.id)
    rec_id = best[1] if best else None
    if room is None and rec_id is not None:
        room_id = next(r.room for r in station.receptacles if r.id == rec_id) or None
    else:
        room_id = room.id if room else None
    return PlacedObject(name, type_, position, level, cell, room_id, rec_id)


def location_key(text: str) -> str:
    """A comparable key for room names and schedule codes: ``Bedroom_0`` ~ ``bed room 0``, ``OfficeRoom01`` ~
    ``office room 1``, ``OfficeSpaceRoom`` ~ ``office space`` (lower case, no separators, no word ``room``,
    no leading zeros)."""
    text = re.sub(r"(?<=[a-z])(?=[A-Z0-9])", " ", text).lower()
    text = re.sub(r"[^a-z0-9]", "", text).replace("room", "")
    return re.sub(r"(?<!\d)0+(?=\d)", "", text)


def code_floor(code: str) -> int | None:
    """The floor level of a PRS location code: ``F1_...`` is floor 0 (``semantic_map_0``), ``F3`` floor 2."""
    m = re.match(r"F(\d+)_", code)
    return int(m.group(1)) - 1 if m else None


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
        from gsr.benchmarks.delivery.building.prs_calibrate import calibrate_station, observations_from_tasks

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
