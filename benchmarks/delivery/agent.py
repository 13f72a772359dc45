"""Baseline delivery agent: parse, search the building graph for the object, pick, find the person.

The agent knows the building graph without its objects (rooms, receptacles, connectors: a map) and the
residents' profiles and published routines, not where anyone actually is. It parses the instruction,
visits candidate receptacles nearest-first (hinted ones first, then rooms where that kind of object
lives), picks the object (retrying slipped grasps), then looks for the person: where it last saw them,
the room the instruction names, where their routine puts them now, their home room, then everywhere
else nearest-first, re-approaching when they have moved on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from gsr.benchmarks.delivery.building.catalog import OBJECTS
from gsr.benchmarks.delivery.building.graph import building_graph
from gsr.benchmarks.delivery.building.model import Building, Person, Place
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.knowledge import BuildingKnowledge
from gsr.benchmarks.delivery.parser import InstructionParser
from gsr.benchmarks.delivery.reference import ObjectRef, PersonRef, Reference
from gsr.benchmarks.delivery.world import DeliveryWorld, Observation

from gsr.errors import GSRError

PICK_TRIES = 3
APPROACH_TRIES = 4
SIGHTING_FRESH = 240.0  # seconds a sighting is trusted as "they are probably still there"


@dataclass
class AgentTrace:
    """What the agent understood and decided (for the report)."""

    parsed: Reference | None = None
    parse_error: str | None = None
    person: str | None = None
    item: str | None = None
    notes: list[str] = field(default_factory=list)


def resolve_person(people: tuple[Person, ...], ref: PersonRef) -> list[str]:
    """Ids of the people matching a person reference (name wins; otherwise every described feature)."""
    if ref.name:
        return [p.id for p in people if p.id == ref.name]
    out = []
    for p in people:
        a = p.appearance
        if ref.role and p.role != ref.role:
            continue
        if ref.gender and a.gender != ref.gender:
            continue
        if ref.garment and (a.garment != ref.garment or a.color != ref.color):
            continue
        if ref.hair and a.hair != ref.hair:
            continue
        if ref.glasses is not None and a.glasses != ref.glasses:
            continue
        out.append(p.id)
    return out


class BaselineAgent:
    """The search-based baseline for one building."""

    def __init__(
        self, building: Building, bmap: BuildingMap, parser: InstructionParser, use_routines: bool = True
    ) -> None:
        """Precompute the map knowledge the agent uses; ``use_routines=False`` is the ablation that
        searches for people without their published routines (home room and nearest rooms only)."""
        self.building, self.bmap, self.parser = building, bmap, parser
        self.use_routines = use_routines
        self.map_graph = building_graph(building, items=False, room_of_place=bmap.room_at)
        self.knowledge = BuildingKnowledge(self.map_graph, building.cell_size)
        self.lookout: dict[str, Place] = {}
        for room, (floor, cr, cc) in BuildingKnowledge(
            self.map_graph, building.cell_size
        ).room_center.items():
            cells = bmap.free_cells(room)
            r, c = min(cells, key=lambda rc: ((rc[0] - cr) ** 2 + (rc[1] - cc) ** 2, rc))
            self.lookout[room] = (floor, r, c)

    # ------------------------------------------------------------ episode

    def run(self, world: DeliveryWorld) -> AgentTrace:
        """Carry out the task's instruction in ``world`` until delivered, stuck or out of time."""
        trace = AgentTrace()
        try:
            trace.parsed = self.parser.parse(world.task.instruction)
        except GSRError as exc:
            trace.parse_error = str(exc)
            return trace
        people = resolve_person(self.building.people, trace.parsed.person)
        if not people:
            trace.notes.append("no person matches the description")
            return trace
        trace.person = people[0]
        self.knowledge = BuildingKnowledge(
            self.map_graph, self.building.cell_size
        )  # fresh knowledge per episode
        item = self._fetch(world, trace.parsed.object, trace)
        if item is None:
            return trace
        trace.item = item
        self._deliver(world, trace.person, trace.parsed.person, trace)
        return trace

    def _observe(self, world: DeliveryWorld) -> Observation:
        obs = world.look()
        self.knowledge.observe(obs)
        return obs

    def _candidates(self, ref: ObjectRef, widen: bool) -> list[str]:
        recs = self.knowledge.receptacles.values()
        if widen:
            return [r.id for r in recs]
        hinted = [
            r
            for r in recs
            if (ref.room is None or r.room == ref.room)
            and (ref.receptacle is None or r.category == ref.receptacle)
        ]
        if ref.room or ref.receptacle:
            return [r.id for r in hinted]
        kinds = set(OBJECTS[ref.category].rooms) if ref.category in OBJECTS else set()
        kind = self.knowledge.room_kind
        return [r.id for r in hinted if kind[r.room] in kinds] or [r.id for r in hinted]

    def _fetch(self, world: DeliveryWorld, ref: ObjectRef, trace: AgentTrace) -> str | None:
        recs = self.knowledge.receptacles
        checked: set[str] = set()
        looked_rooms: set[str] = set()
        widen = False
        while not world.done:
            found = self.knowledge.items_matching(ref)
            if found:
                iid, rec = found[0]
                if not world.navigate(recs[rec].place):
                    return None
                for _ in range(PICK_TRIES):
                    if world.pick(iid):
                        return iid
                    if world.done:
                        return None
                trace.notes.append(f"could not grasp {iid}")
                self.knowledge.forget(iid)
                continue
            todo = [r for r in self._candidates(ref, widen) if r not in checked]
            if not todo:
                if widen:
                    trace.notes.append("object not found anywhere")
                    return None
                widen = True
                trace.notes.append("hinted places exhausted; searching everywhere")
                continue
            # nearest unchecked receptacle first
            rec = min(todo, key=lambda r: (world.travel_seconds(recs[r].place), r))
            if math.isinf(world.travel_seconds(recs[rec].place)) or not world.navigate(recs[rec].place):
                checked.add(rec)
                if world.done:
                    return None
                continue
            if recs[rec].closed and not world.open(rec):
                return None
            room = recs[rec].room
            if room not in looked_rooms or recs[rec].closed:
                self._observe(world)
                looked_rooms.add(room)
            # one look covers every open receptacle of the room
            checked.update(r.id for r in recs.values() if r.room == room and not r.closed)
            checked.add(rec)
        return None

    # ------------------------------------------------------------ person

    def _room_order(self, world: DeliveryWorld, pid: str, ref: PersonRef, visited: set[str]) -> list[str]:
        person = self.building.person(pid)
        order: list[str] = []
        sighting = self.knowledge.sighting(pid)
        if sighting and world.time - sighting[0] <= SIGHTING_FRESH:
            room = self.bmap.room_at(sighting[1])
            if room:
                order.append(room)
        if ref.room:
            order.append(ref.room)
        now = world.time
        for s in person.routine if self.use_routines else ():
            if s.start <= now < s.end:
                order.append(s.room)
                if s.end - now < 300:  # about to move on: the next slot's room is a good bet too
                    nxt = [x.room for x in person.routine if x.start == s.end]
                    order += nxt
        order.append(person.home_room)
        rest = sorted(
            (r.id for r in self.building.rooms if r.kind != "corridor"),
            key=lambda rid: (world.travel_seconds(self.lookout[rid]), rid),
        )
        order += rest
        out: list[str] = []
        for r in order:
            if r not in out and r not in visited:
                out.append(r)
        return out

    def _deliver(self, world: DeliveryWorld, pid: str, ref: PersonRef, trace: AgentTrace) -> None:
        visited: set[str] = set()
        while not world.done:
            sighting = self.knowledge.sighting(pid)
            if sighting and world.time - sighting[0] <= 1.0:
                # just seen: approach and hand over, re-looking if they moved meanwhile
                for _ in range(APPROACH_TRIES):
                    goal = self._beside(world, sighting[1])
                    if goal is None or not world.navigate(goal):
                        break
                    if world.handover(pid) or world.done:
                        return
                    obs = self._observe(world)
                    if pid not in obs.people:
                        break
                    sighting = self.knowledge.sighting(pid)
                visited.discard(self.bmap.room_at(sighting[1]) or "")
                self.knowledge.forget(pid)
            order = self._room_order(world, pid, ref, visited)
            if not order:
                visited.clear()  # searched everywhere: start another round
                order = self._room_order(world, pid, ref, visited)
                if not order:
                    return
            room = order[0]
            visited.add(room)
            if not world.navigate(self.lookout[room]):
                if world.done:
                    return
                continue
            self._observe(world)

    def _beside(self, world: DeliveryWorld, place: Place) -> Place | None:
        """A free cell next to a person (they stand on a free cell themselves), nearest the robot."""
        f, r, c = place
        options = [
            (f, r + dr, c + dc)
            for dr in (-1, 0, 1)
            for dc in (-1, 0, 1)
            if (dr or dc) and self.bmap.is_walkable((f, r + dr, c + dc))
        ]
        if not options:
            return place
        return min(
            options, key=lambda p: self.bmap.euclidean(world.robot, p) if p[0] == world.robot[0] else 0
        )
