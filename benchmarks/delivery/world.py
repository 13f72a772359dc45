"""The simulated delivery world: a robot acting in a building while people live their day.

Event-driven simulated time: every action advances the clock by its duration (travel time from A* path
length and speed, elevator waits, grasp attempts), so an 8-minute episode runs in milliseconds. People
are wherever ``PeopleClock`` puts them at the current second. The robot holds at most one object.

Success is a state condition (as in PRS): the episode ends successfully as soon as, after any action,
the robot holds the target object within 3 m (walking distance) of the recipient.

Perception model: looking around a room shows the objects on its open receptacles (and inside the ones
the robot opened) and the people in it, identified (the robot knows the residents' faces).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from gsr.benchmarks.delivery.building.catalog import OBJECTS
from gsr.benchmarks.delivery.building.model import Building, Place
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.people import PeopleClock
from gsr.benchmarks.delivery.tasks import DeliveryTask

ROBOT_SPEED = 1.0  # m/s
LOOK_SECONDS = 3.0
OPEN_SECONDS = 4.0
PICK_SECONDS = 10.0
HANDOVER_SECONDS = 5.0
SUCCESS_RADIUS = 3.0
NEAR_RADIUS = 5.0


@dataclass
class Observation:
    """What one look shows: the room, visible objects (id -> (category, colour, receptacle)), people."""

    room: str | None
    time: float
    items: dict[str, tuple[str, str, str]] = field(default_factory=dict)
    people: dict[str, Place] = field(default_factory=dict)


@dataclass
class EpisodeLog:
    """Partial-score bookkeeping (PRS style) filled in while the episode runs."""

    object_found: bool = False
    grasped: bool = False
    person_within_5m: bool = False
    person_within_3m: bool = False
    delivered: bool = False
    timed_out: bool = False
    actions: int = 0
    metres: float = 0.0
    events: list[tuple[float, str]] = field(default_factory=list)  # (elapsed seconds, what happened)


class DeliveryWorld:
    """One episode's world state; actions return results and advance simulated time."""

    def __init__(self, building: Building, bmap: BuildingMap, task: DeliveryTask) -> None:
        """Start the robot where the task says, at the task's time of day."""
        self.building, self.bmap, self.task = building, bmap, task
        self.clock = PeopleClock(building, task.world_seed, bmap)
        self.t0 = float(task.start_time)
        self.time = self.t0
        self.robot: Place = tuple(task.start)  # type: ignore[assignment]
        self.held: str | None = None
        self.item_at = {it.id: it.receptacle for it in building.items}
        self.opened: set[str] = set()
        self.rec = {r.id: r for r in building.receptacles}
        self.items = {it.id: it for it in building.items}
        self.done = False
        self.log = EpisodeLog()
        self._rng = np.random.default_rng([task.world_seed, 7])
        self._note_person()

    # ------------------------------------------------------------ clock

    @property
    def elapsed(self) -> float:
        """Simulated seconds since the episode started."""
        return self.time - self.t0

    @property
    def remaining(self) -> float:
        """Simulated seconds left before the time limit."""
        return self.task.time_limit - self.elapsed

    def _spend(self, seconds: float) -> bool:
        """Advance the clock; False (and the episode ends) if that passes the time limit."""
        self.log.actions += 1
        if self.done:
            return False
        if seconds > self.remaining:
            self.time = self.t0 + self.task.time_limit
            self.done = self.log.timed_out = True
            return False
        self.time += seconds
        return True

    def _event(self, text: str) -> None:
        self.log.events.append((round(self.elapsed, 1), text))

    def _place_name(self, place: Place) -> str:
        room = self.bmap.room_at(place)
        return self.building.room(room).name if room else f"a doorway on floor {place[0]}"

    def _note_person(self) -> None:
        """Update the partial scores; the task succeeds once the target is held within 3 m of the recipient."""
        where = self.clock.location(self.task.person, self.time)
        if where is None or self.bmap.euclidean(self.robot, where) > NEAR_RADIUS:
            return  # walking distance is never shorter than the straight line
        d = self.bmap.distance(self.robot, where)
        self.log.person_within_5m |= d <= NEAR_RADIUS
        self.log.person_within_3m |= d <= SUCCESS_RADIUS
        if d <= SUCCESS_RADIUS and self.held == self.task.item and not self.done:
            self.log.delivered = self.done = True
            self._event(f"success: holding {self.held} within {d:.1f} m of {self.task.person}")

    # ------------------------------------------------------------ actions

    def travel_seconds(self, goal: Place) -> float:
        """Time the robot would need to reach ``goal`` from where it is (inf if unreachable)."""
        route = self.bmap.route(self.robot, goal)
        return math.inf if route is None else route.seconds(ROBOT_SPEED)

    def navigate(self, goal: Place) -> bool:
        """Drive to ``goal`` (elevator between floors); False if unreachable or out of time."""
        route = self.bmap.route(self.robot, goal)
        if route is None or not self.bmap.is_walkable(goal):
            self._event(f"cannot reach {goal}")
            return False
        if not self._spend(route.seconds(ROBOT_SPEED)):
            if self.log.timed_out:
                self._event(f"out of time driving to {self._place_name(goal)}")
            return False
        self.log.metres += route.metres
        self.robot = goal
        via = f" via the {route.connector}" if route.connector else ""
        self._event(f"drove {route.metres:.1f} m{via} to {self._place_name(goal)}")
        self._note_person()
        return True

    def look(self) -> Observation:
        """Look around the current room (costs ``LOOK_SECONDS``)."""
        room = self.bmap.room_at(self.robot)
        if not self._spend(LOOK_SECONDS):
            return Observation(room, self.time)
        obs = Observation(room, self.time)
        if room is None:
            return obs
        for iid, rid in self.item_at.items():
            rec = self.rec.get(rid)
            if rec is None or rec.room != room:
                continue
            if rec.closed and rid not in self.opened:
                continue
            it = self.items[iid]
            obs.items[iid] = (it.category, it.color, rid)
            if iid == self.task.item:
                self.log.object_found = True
        for pid in self.clock.people_in(room, self.time):
            where = self.clock.location(pid, self.time)
            if where is not None:
                obs.people[pid] = where
        people = ", ".join(self.building.person(p).name for p in obs.people) or "nobody"
        self._event(f"looked around {self._place_name(self.robot)}: {len(obs.items)} objects, {people}")
        self._note_person()
        return obs

    def _at(self, rec_id: str) -> bool:
        rec = self.rec[rec_id]
        floor = self.building.room(rec.room).floor
        return self.robot == (floor, *rec.access)

    def open(self, rec_id: str) -> bool:
        """Open a closed receptacle the robot stands at."""
        if rec_id not in self.rec or not self._at(rec_id):
            self._event(f"open {rec_id}: not at it")
            return False
        if not self._spend(OPEN_SECONDS):
            return False
        self.opened.add(rec_id)
        self._event(f"opened {rec_id}")
        return True

    def pick(self, item_id: str) -> bool:
        """One grasp attempt; succeeds with the object type's grasp-success probability."""
        rid = self.item_at.get(item_id)
        if self.held is not None or rid is None or not self._at(rid):
            self._event(f"pick {item_id}: hand full, object gone or robot not at it")
            return False
        if self.rec[rid].closed and rid not in self.opened:
            self._event(f"pick {item_id}: {rid} is closed")
            return False
        if not self._spend(PICK_SECONDS):
            return False
        if self._rng.random() >= OBJECTS[self.items[item_id].category].grasp_success:
            self._event(f"pick {item_id}: grasp slipped")
            return False
        self.held = item_id
        del self.item_at[item_id]
        self._event(f"picked up {item_id} from {rid}")
        if item_id == self.task.item:
            self.log.grasped = self.log.object_found = True
        return True

    def place(self, rec_id: str) -> bool:
        """Put the held object on/in the receptacle the robot stands at."""
        if (
            self.held is None
            or rec_id not in self.rec
            or not self._at(rec_id)
            or not self._spend(PICK_SECONDS)
        ):
            return False
        self.item_at[self.held] = rec_id
        self._event(f"put {self.held} on/in {rec_id}")
        self.held = None
        return True

    def handover(self, person_id: str) -> bool:
        """Hand the held object to a person within reach; handing it to anyone but the recipient ends the
        episode as a failure (the right object to the recipient already succeeded in ``_note_person``)."""
        if self.held is None or not self._spend(HANDOVER_SECONDS):
            return False
        self._note_person()
        if self.done:
            return self.log.delivered
        where = self.clock.location(person_id, self.time)
        if where is None or self.bmap.euclidean(self.robot, where) > SUCCESS_RADIUS:
            return False
        if self.bmap.distance(self.robot, where) > SUCCESS_RADIUS:
            return False
        self.done = True
        self._event(f"handed {self.held} to {person_id}: wrong object or person")
        return True
