"""The building model: floors with occupancy grids, rooms, doors, receptacles, objects, connectors, people.

A ``Building`` is plain, validated data (pydantic, JSON round trip). Grids are stored compactly as one
string per row, one character per cell (``GRID_CHARS``). Coordinates are ``(row, col)`` cells of
``cell_size`` metres; a place in the building is ``(floor, row, col)``. Times are seconds since midnight.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from gsr.errors import GSRError
from gsr.io import read_text, write_text_atomic
from gsr.scene_graph import format_validation_error

T = TypeVar("T")

#: Grid cell codes: free floor, wall, furniture (blocked), door (free), stairs and elevator (blocked).
GRID_CHARS: dict[str, str] = {
    ".": "free",
    "#": "wall",
    "f": "furniture",
    "d": "door",
    "S": "stairs",
    "E": "elevator",
}
#: Cells a robot or person may stand on.
WALKABLE: frozenset[str] = frozenset({".", "d"})

Cell = tuple[int, int]
Place = tuple[int, int, int]  # (floor, row, col)

_MODEL = ConfigDict(frozen=True, extra="forbid")


class Floor(BaseModel):
    """One storey: its level (0 = ground) and occupancy grid rows."""

    model_config = _MODEL
    level: int = Field(ge=0)
    name: str
    grid: tuple[str, ...] = Field(min_length=3)

    @field_validator("grid")
    @classmethod
    def _rectangular(cls, rows: tuple[str, ...]) -> tuple[str, ...]:
        width = len(rows[0])
        for i, row in enumerate(rows):
            if len(row) != width:
                raise ValueError(f"row {i} has {len(row)} cells, row 0 has {width}")
            bad = set(row) - set(GRID_CHARS)
            if bad:
                raise ValueError(
                    f"row {i} has unknown cell codes {sorted(bad)} (known: {''.join(GRID_CHARS)})"
                )
        return rows

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)``."""
        return (len(self.grid), len(self.grid[0]))


class Room(BaseModel):
    """A room: an axis-aligned rectangle of cells ``[r0, r1) x [c0, c1)`` on one floor."""

    model_config = _MODEL
    id: str
    kind: str
    name: str = Field(description="how people call it: 'kitchen', 'office 104'")
    floor: int
    rect: tuple[int, int, int, int]

    @model_validator(mode="after")
    def _rect(self) -> Room:
        r0, c0, r1, c1 = self.rect
        if not (0 <= r0 < r1 and 0 <= c0 < c1):
            raise ValueError(f"room {self.id}: empty or negative rect {self.rect}")
        return self

    def contains(self, row: int, col: int) -> bool:
        """True when cell (row, col) lies inside the room."""
        r0, c0, r1, c1 = self.rect
        return r0 <= row < r1 and c0 <= col < c1


class Door(BaseModel):
    """A doorway cell joining two rooms on a floor."""

    model_config = _MODEL
    floor: int
    cell: tuple[int, int]
    rooms: tuple[str, str]


class Receptacle(BaseModel):
    """Furniture that holds objects: footprint rect, the free cell the robot stands on to reach it."""

    model_config = _MODEL
    id: str
    category: str
    name: str
    room: str
    relation: Literal["on", "in"] = "on"
    closed: bool = False
    rect: tuple[int, int, int, int]
    access: tuple[int, int]


class Item(BaseModel):
    """A movable object resting on or in a receptacle."""

    model_config = _MODEL
    id: str
    category: str
    name: str
    color: str
    receptacle: str


class Connector(BaseModel):
    """Stairs or an elevator: the cell to stand on at each floor and its timing (seconds)."""

    model_config = _MODEL
    id: str
    kind: Literal["stairs", "elevator"]
    access: dict[int, tuple[int, int]] = Field(description="floor level -> access cell")
    seconds_per_floor: float = Field(gt=0, description="climb time (stairs) or ride time (elevator)")
    call_seconds: float = Field(default=0.0, ge=0, description="elevator: mean wait after calling it")
    door_seconds: float = Field(default=0.0, ge=0, description="elevator: doors open+close, each stop")


class Slot(BaseModel):
    """Where a person is in ``[start, end)`` seconds of the day and what they do there."""

    model_config = _MODEL
    start: int = Field(ge=0, le=86400)
    end: int = Field(ge=0, le=86400)
    room: str
    activity: str

    @model_validator(mode="after")
    def _ordered(self) -> Slot:
        if self.end <= self.start:
            raise ValueError(f"slot {self.activity!r} ends ({self.end}) before it starts ({self.start})")
        return self


class Appearance(BaseModel):
    """How a person looks: enough to describe them ('the woman in the blue shirt with glasses')."""

    model_config = _MODEL
    gender: Literal["man", "woman"]
    garment: str
    color: str
    hair: str
    glasses: bool = False


class Person(BaseModel):
    """A character: profile plus the routine (the published daily schedule) that covers the day."""

    model_config = _MODEL
    id: str
    name: str
    role: str
    appearance: Appearance
    home_room: str = Field(description="the room they are based in (office, lab, bedroom ...)")
    routine: tuple[Slot, ...] = Field(min_length=1)

    @model_validator(mode="after")
    def _contiguous(self) -> Person:
        for a, b in zip(self.routine, self.routine[1:], strict=False):
            if a.end != b.start:
                raise ValueError(f"person {self.id}: routine gap or overlap at {a.end} vs {b.start}")
        return self


class Building(BaseModel):
    """A whole building. References between parts are checked on load."""

    model_config = _MODEL
    name: str
    seed: int
    cell_size: float = Field(default=0.5, gt=0, description="metres per grid cell")
    floors: tuple[Floor, ...] = Field(min_length=1)
    rooms: tuple[Room, ...] = Field(min_length=1)
    doors: tuple[Door, ...] = ()
    receptacles: tuple[Receptacle, ...] = ()
    items: tuple[Item, ...] = ()
    connectors: tuple[Connector, ...] = ()
    people: tuple[Person, ...] = ()

    @model_validator(mode="after")
    def _references(self) -> Building:
        levels = {f.level for f in self.floors}
        rooms = {r.id: r for r in self.rooms}
        _unique("room", [r.id for r in self.rooms])
        _unique("receptacle", [r.id for r in self.receptacles])
        _unique("item", [i.id for i in self.items])
        _unique("person", [p.id for p in self.people])
        shapes = {f.level: f.shape for f in self.floors}
        for r in self.rooms:
            if r.floor not in levels:
                raise ValueError(f"room {r.id}: floor {r.floor} does not exist")
            if r.rect[2] > shapes[r.floor][0] or r.rect[3] > shapes[r.floor][1]:
                raise ValueError(f"room {r.id}: rect {r.rect} extends past the floor grid {shapes[r.floor]}")
        for d in self.doors:
            for rid in d.rooms:
                if rid not in rooms:
                    raise ValueError(f"door at {d.cell}: unknown room {rid!r}")
        recs = {r.id for r in self.receptacles}
        for rec in self.receptacles:
            if rec.room not in rooms:
                raise ValueError(f"receptacle {rec.id}: unknown room {rec.room!r}")
            if not rooms[rec.room].contains(*rec.access):
                raise ValueError(f"receptacle {rec.id}: access cell {rec.access} is outside room {rec.room}")
        for it in self.items:
            if it.receptacle not in recs:
                raise ValueError(f"item {it.id}: unknown receptacle {it.receptacle!r}")
        for c in self.connectors:
            if set(c.access) - levels:
                raise ValueError(f"connector {c.id}: unknown floors {sorted(set(c.access) - levels)}")
            for level, (row, col) in c.access.items():
                if not (0 <= row < shapes[level][0] and 0 <= col < shapes[level][1]):
                    raise ValueError(f"connector {c.id}: access cell {(row, col)} is off floor {level}")
        for p in self.people:
            for rid in (p.home_room, *(s.room for s in p.routine)):
                if rid not in rooms:
                    raise ValueError(f"person {p.id}: unknown room {rid!r}")
        return self

    # ------------------------------------------------------------ lookups

    def floor(self, level: int) -> Floor:
        """The floor at ``level``."""
        return _find(self.floors, "level", level, f"floor {level}", self.name)

    def room(self, room_id: str) -> Room:
        """The room ``room_id``."""
        return _find(self.rooms, "id", room_id, f"room {room_id!r}", self.name)

    def receptacle(self, rec_id: str) -> Receptacle:
        """The receptacle ``rec_id``."""
        return _find(self.receptacles, "id", rec_id, f"receptacle {rec_id!r}", self.name)

    def person(self, person_id: str) -> Person:
        """The person ``person_id``."""
        return _find(self.people, "id", person_id, f"person {person_id!r}", self.name)

    # ------------------------------------------------------------ IO

    def to_json(self) -> str:
        """Compact-but-readable JSON (grid rows stay one string each)."""
        return self.model_dump_json(indent=1)

    @classmethod
    def from_json(cls, text: str, source: str = "<string>") -> Building:
        """Parse and validate building JSON; errors name the source and field."""
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise GSRError(f"{source}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise GSRError(f"{source}: invalid building: {format_validation_error(exc)}") from None


def _unique(what: str, ids: list[str]) -> None:
    seen: set[str] = set()
    for i in ids:
        if i in seen:
            raise ValueError(f"duplicate {what} id {i!r}")
        seen.add(i)


def _find(items: Sequence[T], key: str, value: object, what: str, building: str) -> T:
    """The first item whose ``key`` attribute is ``value`` (KeyError naming it and the building)."""
    for item in items:
        if getattr(item, key) == value:
            return item
    raise KeyError(f"no {what} in building {building}")


def load_building(path: str | Path) -> Building:
    """Read a building JSON file (GSRError naming the file on any problem)."""
    p = Path(path)
    return Building.from_json(read_text(p), str(p))


def save_building(building: Building, path: str | Path) -> None:
    """Write a building atomically (temp file + rename), so a failure never leaves half a file."""
    write_text_atomic(Path(path), building.to_json() + "\n")
