"""An offline PRS delivery environment with the simulator's boundary.

The agent gets only what PRS gives a robot (``PrsRequest``: instruction, recipient description, time; the
station's maps and people's published schedules) and acts through this class:

- ``observe()``: objects and people a simulated sensor sees from the robot's pose: in the same room (or
  in a corridor or doorway, in no room), a clear line of sight on the grid (walls, value-0 cells, block
  it; furniture does not), within ``SENSOR_RANGE_M``.
  Objects come as (simulator name, detector type, position, caption words); people as (handle,
  appearance, position, action) -- never by name;
- ``navigate(cell)``: A* on the floor's free cells (8-connected); simulated time = path length /
  ``ROBOT_SPEED_MPS``. The maps mark no stairs or elevator, so a route to another floor fails;
- ``grasp(name)``: an object observed from the current pose, within ``REACH_M``, hand empty;
- ``hand_over(handle)``: ends the task next to the person.

A task ends at ``TIME_LIMIT_S`` simulated seconds. The task's truth (target, person position) stays here.
"""

from __future__ import annotations

import hashlib
import math
import random
from dataclasses import dataclass, field
from datetime import timedelta

import numpy as np
from gsr.benchmarks.delivery.building.navigation import astar, path_cells_length
from gsr.benchmarks.delivery.building.prs_station import Cell, Station
from gsr.benchmarks.delivery.prs_tasks import PlacedObject, PrsTask

ROBOT_SPEED_MPS = 1.0  # metres per second along the path
OBSERVE_S = 3.0  # one look around (a turn in place)
GRASP_S = 15.0  # arm reach, grasp, lift
HANDOVER_S = 5.0
TIME_LIMIT_S = 600.0  # PRS: tasks longer than 10 minutes fail
SENSOR_RANGE_M = 8.0
REACH_M = 1.5  # horizontal distance from the robot's cell centre to the object


@dataclass(frozen=True)
class SeenObject:
    """An object in view: simulator name, detector type, world position, caption words."""

    name: str
    type: str
    position: tuple[float, float, float]
    caption: frozenset[str]


@dataclass(frozen=True)
class SeenPerson:
    """A person in view, by appearance: an opaque handle, appearance, world position, action."""

    handle: str
    appearance: str
    position: tuple[float, float, float]
    action: str


@dataclass(frozen=True)
class Observation:
    """What the sensor returns: the robot's room and the objects and people in view."""

    room: str | None
    objects: tuple[SeenObject, ...]
    people: tuple[SeenPerson, ...]


class ActionError(Exception):
    """An action the environment refuses (the message says why); the episode goes on."""


@dataclass
class _Person:
    handle: str
    person_id: int
    appearance: str
    position: tuple[float, float, float]
    cell: Cell
    floor: int
    action: str


@dataclass
class EnvLog:
    """What happened: path cells per floor, events, the held object, the seconds spent."""

    path: list[tuple[int, Cell]] = field(default_factory=list)
    events: list[str] = field(default_factory=list)


def line_of_sight(blocked: np.ndarray, a: Cell, b: Cell) -> bool:
    """True when no blocked cell lies strictly between cells ``a`` and ``b`` (sampled along the segment)."""
    (i0, j0), (i1, j1) = a, b
    n = max(abs(i1 - i0), abs(j1 - j0))
    for k in range(1, n):
        i = round(i0 + (i1 - i0) * k / n)
        j = round(j0 + (j1 - j0) * k / n)
        if (i, j) != b and blocked[i, j]:
            return False
    return True


class PrsEnv:
    """One delivery episode on the station. ``captions`` maps object names to caption words (optional)."""

    def __init__(
        self,
        station: Station,
        objects: list[PlacedObject],
        task: PrsTask,
        captions: dict[str, frozenset[str]] | None = None,
    ) -> None:
        self.station = station
        self.request = task.request
        self._truth = task.truth
        self._objects = {o.name: o for o in objects if o.cell is not None}
        self._captions = captions or {}
        target = self._objects.get(task.truth.target_object_name)
        level = (
            target.floor
            if target is not None
            else min(lvl for lvl, f in station.floors.items() if f.transform is not None)
        )
        self.floor = level
        self.cell = start_cell(station, level)
        self.seconds = 0.0
        self.held: str | None = None
        self.done = False
        self.log = EnvLog(path=[(level, self.cell)])
        self._seen: set[str] = set()
        self._people = self._place_people()

    # ---- the simulated world -------------------------------------------------------------------------
    def _place_people(self) -> list[_Person]:
        """The recipient at the task's position; everyone else at a spot of the room their schedule names
        at that time of the hour (deterministic per task)."""
        out = []
        t = self.request.time
        for pid, person in sorted(self.station.people.items()):
            handle = "person-" + hashlib.sha1(f"{self.request.task_id}/{pid}".encode()).hexdigest()[:8]
            if pid == self._truth.npc_id:
                pos = self._truth.npc_position
                where = self.station.locate(*pos)
                action = self._truth.npc_action
            else:
                slots = person.slots_at(t.hour)
                if not slots:
                    continue
                slot = slots[min(len(slots) - 1, t.minute * len(slots) // 60)]
                room = self.station.room_of_location(slot.location)
                floor = self.station.floors.get(room.floor) if room else None
                if room is None or floor is None or floor.transform is None:
                    continue
                i0, i1, j0, j1 = room.box
                cells = np.argwhere(floor.walkable[i0 : i1 + 1, j0 : j1 + 1]) + np.array([i0, j0])
                if not len(cells):
                    continue
                rng = random.Random(f"{self.request.task_id}/{pid}")
                ci, cj = (int(v) for v in cells[rng.randrange(len(cells))])
                x, z = floor.transform.to_world(ci, cj)
                pos = (x, floor.transform.height, z)
                where = (room.floor, (ci, cj))
                action = slot.actions[0] if slot.actions else "stand"
            if where is None:
                continue
            out.append(_Person(handle, pid, person.character, pos, where[1], where[0], action))
        return out

    def world(self, cell: Cell, floor: int | None = None) -> tuple[float, float, float]:
        """World position of a cell's centre on a floor (default: the robot's)."""
        f = self.station.floors[self.floor if floor is None else floor]
        assert f.transform is not None
        x, z = f.transform.to_world(*cell)
        return (x, f.transform.height, z)

    @property
    def cell_size(self) -> float:
        """Metres per grid cell on the robot's floor."""
        t = self.station.floors[self.floor].transform
        assert t is not None
        return t.scale

    def _spend(self, seconds: float) -> None:
        self.seconds += seconds
        if self.seconds >= TIME_LIMIT_S:
            self.done = True

    # ---- actions -------------------------------------------------------------------------------------
    def observe(self) -> Observation:
        """Objects and people visible from the robot's pose."""
        self._check_running()
        self._spend(OBSERVE_S)
        floor = self.station.floors[self.floor]
        room = self.station.room_at(self.floor, self.cell)
        blocked = floor.grid == 0
        rng = SENSOR_RANGE_M / self.cell_size

        def visible(level: int, cell: Cell) -> bool:
            if level != self.floor:
                return False
            rows, cols = floor.shape
            cell = (min(max(cell[0], 0), rows - 1), min(max(cell[1], 0), cols - 1))  # just off the map's edge
            there = self.station.room_at(level, cell)
            # the same room; or a corridor / doorway cell (no room) seen through an open doorway
            if there is not None and there.id != (room.id if room else None):
                return False
            if math.dist(cell, self.cell) > rng:
                return False
            return line_of_sight(blocked, self.cell, cell)

        objs = []
        for o in self._objects.values():
            if (
                o.name != self.held
                and o.floor is not None
                and o.cell is not None
                and visible(o.floor, o.cell)
            ):
                objs.append(SeenObject(o.name, o.type, o.position, self._captions.get(o.name, frozenset())))
                self._seen.add(o.name)
        people = tuple(
            SeenPerson(p.handle, p.appearance, p.position, p.action)
            for p in self._people
            if visible(p.floor, p.cell)
        )
        self.log.events.append(
            f"{self.seconds:.0f}s observe {room.name if room else 'corridor'}: "
            f"{len(objs)} objects, {len(people)} people"
        )
        return Observation(room.id if room else None, tuple(objs), people)

    def navigate(self, goal: Cell, floor: int | None = None) -> float:
        """Drive to a free cell; returns the metres driven. Refuses other floors (no connector mapped)."""
        self._check_running()
        if floor is not None and floor != self.floor:
            raise ActionError(
                f"no stairs or elevator connects floor {self.floor} to floor {floor} on the maps"
            )
        walkable = self.station.floors[self.floor].walkable
        try:
            path = astar(walkable, self.cell, goal)
        except ValueError as exc:
            raise ActionError(str(exc)) from None
        if path is None:
            raise ActionError(f"no path from {self.cell} to {goal}")
        metres = path_cells_length(path) * self.cell_size
        self._spend(metres / ROBOT_SPEED_MPS)
        self.cell = goal
        self.log.path.extend((self.floor, c) for c in path[1:])
        return metres

    def grasp(self, name: str) -> None:
        """Grasp an object observed from here, within reach, with an empty hand."""
        self._check_running()
        if self.held is not None:
            raise ActionError(f"hand is not empty (holding {self.held})")
        obj = self._objects.get(name)
        if obj is None or name not in self._seen:
            raise ActionError(f"{name} has not been observed")
        here = self.world(self.cell)
        if (
            obj.floor != self.floor
            or math.dist((here[0], here[2]), (obj.position[0], obj.position[2])) > REACH_M
        ):
            raise ActionError(f"{name} is out of reach")
        self._spend(GRASP_S)
        self.held = name
        self.log.events.append(f"{self.seconds:.0f}s grasp {name}")

    def hand_over(self, handle: str) -> None:
        """Hand the held object to a person next to the robot; ends the task."""
        self._check_running()
        self._spend(HANDOVER_S)
        self.done = True
        self.log.events.append(f"{self.seconds:.0f}s hand over to {handle}")

    def give_up(self, reason: str) -> None:
        """End the task where the robot stands."""
        self.done = True
        self.log.events.append(f"{self.seconds:.0f}s give up: {reason}")

    def _check_running(self) -> None:
        if self.done:
            raise ActionError("the task has ended (time limit or hand-over)")

    # ---- the evaluator's view ------------------------------------------------------------------------
    def result(self) -> dict:
        """PRS's result fields for this episode (the agent's side only)."""
        x, y, z = self.world(self.cell)
        end = self.request.time + timedelta(seconds=round(self.seconds, 3))
        return {
            "task_id": self.request.task_id,
            "npc_id": self._truth.npc_id,
            "agent_object_name": self.held,
            "agent_position": {"x": x, "y": y, "z": z},
            "start_time": self.request.time.isoformat(),
            "end_time": end.isoformat(),
        }

    def truth_cells(self) -> dict:
        """For reports: the target object's and the recipient's floor and cell (evaluator side)."""
        obj = self._objects.get(self._truth.target_object_name)
        person = next((p for p in self._people if p.person_id == self._truth.npc_id), None)
        return {
            "object": (obj.floor, obj.cell) if obj else None,
            "person": (person.floor, person.cell) if person else None,
            "object_seen": self._truth.target_object_name in self._seen,
        }


def start_cell(station: Station, level: int) -> Cell:
    """Where the robot starts on a floor: the free corridor cell (in no room) nearest the grid's centre."""
    floor = station.floors[level]
    free = np.argwhere(floor.walkable & (floor.room_of < 0))
    if not len(free):
        free = np.argwhere(floor.walkable)
    centre = np.array(floor.shape) / 2
    k = int(np.argmin(((free - centre) ** 2).sum(1)))
    return (int(free[k][0]), int(free[k][1]))
