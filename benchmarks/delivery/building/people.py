"""People: profiles, published routines, and the day they actually live (deterministic per seed).

A person's ``routine`` is what everyone (the robot included) knows: "Imani works in office 104, has lunch
in the dining room at noon". The ``daily_schedule`` for a world seed is what really happens that day:
slot boundaries drift by a few minutes, some slots are spent elsewhere, short errands interrupt work.
Within a slot a person stands at one free cell of the room, re-chosen every ``MOVE_EVERY`` seconds;
between slots in different rooms they walk the A* path from one room to the other.
"""

from __future__ import annotations

import bisect
import itertools
import math
from dataclasses import dataclass

import numpy as np
from gsr.benchmarks.delivery.building.catalog import COLORS, ROLES
from gsr.benchmarks.delivery.building.model import Appearance, Building, Cell, Person, Place, Slot
from gsr.benchmarks.delivery.building.navigation import BuildingMap, path_cells_length

MOVE_EVERY = 180  # seconds a person stays on one spot inside a room
WALK_SPEED = 1.2  # m/s when walking between rooms
MAX_TRANSIT = 900  # s; no walk between rooms takes longer (so later queries skip path finding)
DAY_START, DAY_END = 7 * 3600, 22 * 3600

NAMES: tuple[tuple[str, str], ...] = (
    ("Imani", "woman"), ("Marco", "man"), ("Aiko", "woman"), ("Lucas", "man"), ("Priya", "woman"),
    ("Omar", "man"), ("Sofia", "woman"), ("Chen", "man"), ("Fatima", "woman"), ("David", "man"),
    ("Elena", "woman"), ("Kwame", "man"), ("Yuki", "woman"), ("Mateo", "man"), ("Amara", "woman"),
    ("Noah", "man"), ("Leila", "woman"), ("Ivan", "man"), ("Grace", "woman"), ("Ravi", "man"),
)  # fmt: skip
HAIR: tuple[str, ...] = ("black hair", "brown hair", "blond hair", "gray hair", "red hair", "curly hair")
_GARMENT_COLORS = {"coat": ("white",), "scrubs": ("blue", "green"), "apron": ("white", "black")}
_SOCIAL = ("kitchen", "dining_room", "lounge", "leisure_room", "living_room")


def make_people(rooms: list[dict], rng: np.random.Generator, count: int) -> list[Person]:
    """``count`` characters with roles whose workplaces exist, appearances and routines."""
    by_kind: dict[str, list[str]] = {}
    for r in rooms:
        by_kind.setdefault(r["kind"], []).append(r["id"])
    roles = [r for r in ROLES.values() if r.workplace in by_kind]
    if not roles:
        raise ValueError("no room hosts any role's workplace")
    order = [roles[int(i)] for i in rng.permutation(len(roles))]
    names = [NAMES[int(i)] for i in rng.permutation(len(NAMES))][:count]
    if count > len(NAMES):
        raise ValueError(f"at most {len(NAMES)} people are supported, asked for {count}")
    used_home: dict[str, int] = {}
    people = []
    for i, (name, gender) in enumerate(names):
        role = order[i % len(order)]
        homes = by_kind[role.workplace]
        # spread people of one kind of workplace over its rooms (offices, bedrooms)
        k = used_home.get(role.workplace, int(rng.integers(len(homes))))
        used_home[role.workplace] = k + 1
        home = homes[k % len(homes)]
        garment = role.garments[int(rng.integers(len(role.garments)))]
        colors = _GARMENT_COLORS.get(garment, COLORS[:9])
        look = Appearance(
            gender=gender,  # type: ignore[arg-type]
            garment=garment,
            color=colors[int(rng.integers(len(colors)))],
            hair=HAIR[int(rng.integers(len(HAIR)))],
            glasses=bool(rng.random() < 0.3),
        )
        routine = _routine(home, by_kind, rng)
        people.append(
            Person(
                id=name.lower(), name=name, role=role.role, appearance=look, home_room=home, routine=routine
            )
        )
    return people


def _pick(
    by_kind: dict[str, list[str]], kinds: tuple[str, ...], rng: np.random.Generator, default: str
) -> str:
    options = [rid for k in kinds for rid in by_kind.get(k, [])]
    return options[int(rng.integers(len(options)))] if options else default


def _routine(home: str, by_kind: dict[str, list[str]], rng: np.random.Generator) -> tuple[Slot, ...]:
    """A working day: coffee, work, break, work, lunch, work (maybe a meeting or a workout), evening."""
    lunch_room = _pick(by_kind, ("dining_room", "kitchen"), rng, home)
    plan: list[tuple[int, str, str]] = [
        (int(rng.integers(20, 46)) * 60, _pick(by_kind, _SOCIAL[:3], rng, home), "morning coffee"),
        (int(rng.integers(100, 160)) * 60, home, "working"),
        (int(rng.integers(15, 26)) * 60, _pick(by_kind, _SOCIAL, rng, home), "break"),
        (int(rng.integers(60, 100)) * 60, home, "working"),
        (int(rng.integers(40, 61)) * 60, lunch_room, "lunch"),
        (int(rng.integers(60, 120)) * 60, home, "working"),
    ]
    if rng.random() < 0.5 and "meeting_room" in by_kind:
        plan.append((int(rng.integers(30, 61)) * 60, _pick(by_kind, ("meeting_room",), rng, home), "meeting"))
    else:
        plan.append(
            (
                int(rng.integers(30, 61)) * 60,
                _pick(by_kind, ("gym", "library", "medical_room"), rng, home),
                "errand",
            )
        )
    plan += [
        (int(rng.integers(60, 120)) * 60, home, "working"),
        (int(rng.integers(15, 26)) * 60, _pick(by_kind, _SOCIAL, rng, home), "break"),
        (int(rng.integers(60, 100)) * 60, home, "working"),
        (
            int(rng.integers(60, 120)) * 60,
            _pick(by_kind, ("gym", "leisure_room", "living_room", "lounge"), rng, home),
            "leisure",
        ),
    ]
    slots = []
    t = DAY_START
    for duration, room, activity in plan:
        if t >= DAY_END:
            break
        end = min(t + duration, DAY_END)
        slots.append(Slot(start=t, end=end, room=room, activity=activity))
        t = end
    if t < DAY_END:
        slots.append(Slot(start=t, end=DAY_END, room=home, activity="evening"))
    return tuple(slots)


def daily_schedule(building: Building, person: Person, seed: int) -> tuple[Slot, ...]:
    """The day ``person`` actually lives under world ``seed``: the routine with drift, detours and errands."""
    index = [p.id for p in building.people].index(person.id)
    rng = np.random.default_rng([seed, index, 1])
    rooms = [r.id for r in building.rooms if r.kind != "corridor"]
    routine = list(person.routine)
    # boundaries drift by up to 8 minutes but never cross each other
    bounds = [s.start for s in routine] + [routine[-1].end]
    for i in range(1, len(bounds) - 1):
        lo, hi = bounds[i - 1] + 120, routine[i].end - 120
        bounds[i] = int(np.clip(bounds[i] + int(rng.integers(-480, 481)), lo, max(lo, hi)))
    out: list[Slot] = []
    for i, s in enumerate(routine):
        start, end = bounds[i], bounds[i + 1]
        if end <= start:
            continue
        room = s.room
        if rng.random() < 0.15:  # spends this slot somewhere else entirely
            room = rooms[int(rng.integers(len(rooms)))]
            out.append(Slot(start=start, end=end, room=room, activity=f"{s.activity} (elsewhere)"))
            continue
        if s.activity == "working" and end - start > 40 * 60 and rng.random() < 0.35:
            # a short errand in the middle of a work block
            length = int(rng.integers(8, 21)) * 60
            at = start + int(rng.integers(10 * 60, end - start - length - 5 * 60 + 1))
            errand = rooms[int(rng.integers(len(rooms)))]
            out += [
                Slot(start=start, end=at, room=room, activity=s.activity),
                Slot(start=at, end=at + length, room=errand, activity="errand"),
                Slot(start=at + length, end=end, room=room, activity=s.activity),
            ]
            continue
        out.append(Slot(start=start, end=end, room=room, activity=s.activity))
    return tuple(out)


@dataclass
class _Day:
    starts: list[int]
    slots: tuple[Slot, ...]


@dataclass(frozen=True)
class _Transit:
    """A walk between two rooms at the start of a slot: floor paths and the connector ride between."""

    legs: tuple[tuple[int, tuple[Cell, ...]], ...]  # (floor, path) walked in order
    ride: float  # seconds in the elevator / stairwell between the legs (0 on one floor)

    def duration(self) -> float:
        """Seconds the whole transit takes."""
        return sum(_length(p) for _, p in self.legs) * self._cell / WALK_SPEED + self.ride

    _cell: float = 0.5

    def at(self, dt: float) -> Place | None:
        """Where the walker is ``dt`` seconds into the transit (None while riding between floors)."""
        metres = dt * WALK_SPEED
        first_floor, first = self.legs[0]
        first_len = _length(first) * self._cell
        if metres <= first_len:
            return (first_floor, *_along(first, metres / self._cell))
        if len(self.legs) == 1:
            return (first_floor, *first[-1])
        if dt < first_len / WALK_SPEED + self.ride:
            return None
        floor, path = self.legs[1]
        return (floor, *_along(path, (metres - first_len - self.ride * WALK_SPEED) / self._cell))


def _length(path: tuple[Cell, ...]) -> float:
    return path_cells_length(list(path))


def _along(path: tuple[Cell, ...], cells: float) -> Cell:
    """The path cell reached after walking ``cells`` cell-lengths along it."""
    done = 0.0
    for a, b in itertools.pairwise(path):
        done += math.sqrt(2.0) if a[0] != b[0] and a[1] != b[1] else 1.0
        if done > cells:
            return a
    return path[-1]


class PeopleClock:
    """Where everyone is at any second of one day, for a building and a world seed (deterministic).

    Within a slot a person stands on one free cell of the slot's room (re-chosen every ``MOVE_EVERY``
    seconds); when a slot moves them to another room they first walk there at ``WALK_SPEED`` along
    the A* path (stairs or elevator between floors), so they can be met in corridors and doorways.
    """

    def __init__(self, building: Building, seed: int, bmap: BuildingMap) -> None:
        """Compute everyone's day for ``seed``; ``bmap`` gives free cells and paths."""
        self.building = building
        self.seed = seed
        self.bmap = bmap
        self._index = {p.id: i for i, p in enumerate(building.people)}
        self._days: dict[str, _Day] = {}
        self._transits: dict[tuple[str, int], _Transit | None] = {}
        for p in building.people:
            slots = daily_schedule(building, p, seed)
            self._days[p.id] = _Day([s.start for s in slots], slots)

    def schedule(self, person_id: str) -> tuple[Slot, ...]:
        """The actual day of one person."""
        return self._days[person_id].slots

    def _slot_index(self, person_id: str, t: float) -> int | None:
        day = self._days[person_id]
        i = bisect.bisect_right(day.starts, int(t)) - 1
        if i < 0 or t >= day.slots[i].end:
            return None
        return i

    def slot_at(self, person_id: str, t: float) -> Slot | None:
        """The slot a person is in at time ``t`` (None outside the day: not in the building)."""
        i = self._slot_index(person_id, t)
        return None if i is None else self._days[person_id].slots[i]

    def _spot(self, person_id: str, slot: Slot, window: int) -> Place:
        room = self.building.room(slot.room)
        cells = self.bmap.free_cells(slot.room)
        rng = np.random.default_rng([self.seed, self._index[person_id], slot.start, window, 2])
        r, c = cells[int(rng.integers(len(cells)))]
        return (room.floor, r, c)

    def _transit(self, person_id: str, i: int) -> _Transit | None:
        key = (person_id, i)
        if key not in self._transits:
            self._transits[key] = self._make_transit(person_id, i)
        return self._transits[key]

    def _make_transit(self, person_id: str, i: int) -> _Transit | None:
        slots = self._days[person_id].slots
        if i == 0 or slots[i - 1].room == slots[i].room:
            return None
        prev = slots[i - 1]
        a = self._spot(person_id, prev, (prev.end - 1 - prev.start) // MOVE_EVERY)
        b = self._spot(person_id, slots[i], 0)
        cell = self.building.cell_size
        if a[0] == b[0]:
            path = self.bmap.path(a[0], a[1:], b[1:])
            return None if path is None else _Transit(((a[0], path),), 0.0, cell)
        route = self.bmap.route(a, b, allow_stairs=True)
        if route is None or route.connector is None:
            return None
        con = next(c for c in self.building.connectors if c.id == route.connector)
        p1 = self.bmap.path(a[0], a[1:], con.access[a[0]])
        p2 = self.bmap.path(b[0], con.access[b[0]], b[1:])
        if p1 is None or p2 is None:
            return None
        return _Transit(((a[0], p1), (b[0], p2)), route.connector_seconds, cell)

    def in_transit(self, person_id: str, t: float) -> bool:
        """True while a person is walking (or riding) from one slot's room to the next."""
        i = self._slot_index(person_id, t)
        if i is None:
            return False
        start = self._days[person_id].slots[i].start
        if t - start >= MAX_TRANSIT:
            return False
        tr = self._transit(person_id, i)
        return tr is not None and t < start + tr.duration()

    def location(self, person_id: str, t: float) -> Place | None:
        """``(floor, row, col)`` of a person at time ``t``; None when not in the building or riding."""
        i = self._slot_index(person_id, t)
        if i is None:
            return None
        slot = self._days[person_id].slots[i]
        tr = self._transit(person_id, i) if t - slot.start < MAX_TRANSIT else None
        if tr is not None and t < slot.start + tr.duration():
            return tr.at(t - slot.start)
        return self._spot(person_id, slot, int(t - slot.start) // MOVE_EVERY)

    def people_in(self, room_id: str, t: float) -> list[str]:
        """Ids of the people standing in a room at time ``t``."""
        out = []
        for pid in self._days:
            where = self.location(pid, t)
            if where is not None and self.bmap.room_at(where) == room_id:
                out.append(pid)
        return out
