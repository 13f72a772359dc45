"""The PRS research station as a building model: floors, rooms, receptacles, free space, people, schedules.

The types a loaded station is made of (``Station``, ``Floor``, ``Room``, ``Receptacle``, ``Person``,
``GridTransform``) and what is derived from them alone: ``place_object`` (an object of the inventory at its
world position, with the floor, cell, room and receptacle it lies on), ``location_key``, ``code_floor``.
``gsr.benchmarks.delivery.building.prs`` reads a PRS data folder into a ``Station``;
``gsr.benchmarks.delivery.building.prs_calibrate`` fits each floor's grid <-> world transform.

Grid coordinates are ``(i, j)`` = (row, column) of the semantic map; PRS's world frame has ``x`` along ``i``
and ``z`` along ``j`` (``x = x0 + i * scale``, ``z = z0 + j * scale``), ``y`` up.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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
