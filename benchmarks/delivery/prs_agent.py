"""The PRS delivery agent: parse the request, search for the object, grasp it, find the person, hand over.

Everything it uses is what PRS gives a robot -- the request, the recipient's description, the clock, the
station's maps and the people's schedules -- plus what its sensor returns. Each step is checked against
the station model before it is tried (a reachable standing cell in the right room, the object within
reach, the hand empty); the environment checks again and refuses what is not possible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from gsr.benchmarks.delivery.building.prs_graph import station_graph
from gsr.benchmarks.delivery.building.prs_station import Cell, Person, Room, Station
from gsr.benchmarks.delivery.prs_env import (
    REACH_M,
    SENSOR_RANGE_M,
    ActionError,
    Observation,
    PrsEnv,
    SeenObject,
    SeenPerson,
    line_of_sight,
)
from gsr.benchmarks.delivery.prs_parse import (
    STOP,
    ParsedRequest,
    RequestParseError,
    RoomMatcher,
    base_color,
    label_score,
    label_words,
    normalise,
    parse_request,
    words,
)
from scipy import ndimage

#: An object whose caption shares at least this fraction of the request's attribute words is taken at once.
GOOD_CAPTION = 0.5
#: Simulated seconds after which the object search takes the best candidate seen (a third of the limit
#: is kept for finding the person).
SEARCH_BUDGET_S = 400.0
#: A room whose free cells the first viewpoint sees at least this fraction of gets no second look.
COVERAGE = 0.9


@dataclass
class Outcome:
    """How the episode went from the agent's side: what it found and why it stopped."""

    parsed: bool = False
    object_seen: bool = False
    grasped: str | None = None
    person_seen: bool = False
    delivered: bool = False
    reason: str = ""
    steps: list[str] = field(default_factory=list)


def contradicts(colors: set[str], caption: frozenset[str]) -> bool:
    """Whether a caption's colours rule out the requested ones (both said, none shared)."""
    seen = {c for c in (base_color(w) for w in caption) if c}
    return bool(colors and seen and not colors & seen)


class PrsAgent:
    """A rule-free search agent over the station model: rankings from the request, schedules and maps."""

    def __init__(self, station: Station, labels: list[str]) -> None:
        self.station = station
        self.labels = sorted(labels)
        self.rooms = RoomMatcher(station)
        # the station's scene graph (no objects, no people: what the robot knows a priori); its
        # ``adjacent`` edges between rooms are the doorways the person search widens through
        graph = station_graph(station)
        self.neighbours: dict[str, list[str]] = {}
        room_ids = {r.id.lower(): r.id for r in station.rooms}  # graph ids are lower case
        for e in graph.edges:
            if e.relation == "adjacent" and e.source in room_ids and e.target in room_ids:
                self.neighbours.setdefault(room_ids[e.source], []).append(room_ids[e.target])
        self._components = {
            lvl: ndimage.label(f.walkable, structure=np.ones((3, 3), dtype=int))[0]
            for lvl, f in station.floors.items()
        }

    # ---- helpers over the station model --------------------------------------------------------------
    def identify(self, npc_information: str) -> Person | None:
        """The person whose description template, filled with a name, is the given description."""
        norm = " ".join(npc_information.split())
        for p in self.station.people.values():
            head, _, tail = p.description.partition("{name}")
            if norm.startswith(" ".join(head.split())) and norm.endswith(" ".join(tail.split())):
                return p
        return None

    def stand_near(self, env: PrsEnv, box: tuple[int, int, int, int], room: str | None) -> Cell | None:
        """The reachable free cell (in ``room`` when given) nearest a grid box."""
        floor = self.station.floors[env.floor]
        comp = self._components[env.floor]
        label = comp[env.cell]
        mask = (comp == label) & floor.walkable
        if room is not None:
            k = next((n for n, r in enumerate(self.station.rooms) if r.id == room), None)
            if k is not None:
                mask &= floor.room_of == k
        cells = np.argwhere(mask)
        if not len(cells):
            return None
        i0, i1, j0, j1 = box
        di = np.maximum(np.maximum(i0 - cells[:, 0], cells[:, 0] - i1), 0)
        dj = np.maximum(np.maximum(j0 - cells[:, 1], cells[:, 1] - j1), 0)
        k = int(np.argmin(di * di + dj * dj))
        return (int(cells[k][0]), int(cells[k][1]))

    def _cell_of(self, env: PrsEnv, pos: tuple[float, float, float]) -> Cell | None:
        where = self.station.locate(*pos)
        return where[1] if where and where[0] == env.floor else None

    def _go(self, env: PrsEnv, cell: Cell, out: Outcome) -> bool:
        try:
            if cell != env.cell:
                env.navigate(cell)
            return True
        except ActionError as exc:
            out.steps.append(f"navigate refused: {exc}")
            return False

    # ---- the episode ---------------------------------------------------------------------------------
    def run(self, env: PrsEnv) -> Outcome:
        """Run one episode to its end; the outcome says what happened and why it stopped."""
        out = Outcome()
        try:
            parsed = parse_request(env.request.instruction, self.rooms, self.labels)
        except RequestParseError as exc:
            out.reason = f"request not understood: {exc}"
            env.give_up(out.reason)
            return out
        out.parsed = True
        try:
            self._episode(env, parsed, out)
        except ActionError as exc:  # an action after the time limit ended the task
            out.reason = "time limit" if env.done else f"action refused: {exc}"
            out.delivered = False
        return out

    def _episode(self, env: PrsEnv, parsed: ParsedRequest, out: Outcome) -> Outcome:
        person = self.identify(env.request.npc_information)
        obj = self._fetch(env, parsed, out)
        if obj is None or env.done:
            out.reason = out.reason or ("time limit" if env.done else "object not found")
            if not env.done:
                env.give_up(out.reason)
            return out
        self._deliver(env, parsed, person, out)
        return out

    def _fetch(self, env: PrsEnv, parsed: ParsedRequest, out: Outcome) -> SeenObject | None:
        scores = {lab: label_score(lab, parsed.object_tokens) for lab in self.labels}
        top = max(scores.values())
        wanted = {lab for lab, s in scores.items() if s == top and s > 0}
        type_words = {w for lab in wanted for w in label_words(lab)}
        attrs = {t for t in parsed.object_tokens if t not in type_words and t not in STOP}
        src = set(normalise(" ".join(parsed.source_tokens)).split()) - STOP
        want_colors = {c for ph in parsed.objects for c in ph.colors}

        def rec_score(name: str) -> float:
            w = set(words(name))
            return len(w & src) / len(w) if w else 0.0

        here = env.cell
        rooms = list(parsed.source_rooms)
        if not rooms:  # no room named: the rooms holding the best-matching receptacles, then every room
            on_floor = [r for r in self.station.receptacles if r.floor == env.floor and r.room]
            top = max((rec_score(r.name) for r in on_floor), default=0.0)
            named = sorted(
                (r for r in on_floor if top > 0 and rec_score(r.name) == top),
                key=lambda r: math.dist(r.centre, here),
            )
            rooms = list(dict.fromkeys(r.room for r in named))
            rooms += [r.id for r in self.station.rooms if r.floor == env.floor and r.id not in rooms]
        recs = [r for r in self.station.receptacles if r.room in rooms and r.floor == env.floor]
        recs.sort(key=lambda r: (-rec_score(r.name), rooms.index(r.room), math.dist(r.centre, here)))
        best: tuple[tuple, SeenObject] | None = None
        looked: set[Cell] = set()
        for rec in recs:
            if env.done:
                return None
            if best is not None and env.seconds > SEARCH_BUDGET_S:
                break  # leave time to deliver: take the best object seen so far
            stand = self.stand_near(env, rec.box, rec.room)
            if stand is None or stand in looked or not self._go(env, stand, out):
                continue
            looked.add(stand)
            seen = env.observe()
            for o in seen.objects:
                if o.type not in wanted:
                    continue
                out.object_seen = True
                # Dice overlap of the request's attribute words and the caption: "light green" is nearer
                # a caption {green} than {pale, green}
                cap = (
                    2 * len(attrs & o.caption) / (len(attrs) + len(o.caption)) if attrs and o.caption else 0.0
                )
                if cap == 0 and contradicts(want_colors, o.caption):
                    cap = -1.0  # "the sky blue cake" is not the one seen as red and white
                on = self._receptacle_of(env, o)
                key = (cap, rec_score(on) if on else 0.0)
                if best is None or key > best[0]:
                    best = (key, o)
            uncaptioned = (
                best is not None
                and best[0][0] == 0
                and not best[1].caption
                and not any(o.caption and o.caption & attrs for o in seen.objects if o.type in wanted)
            )
            if best is not None and (
                not attrs or best[0][0] >= GOOD_CAPTION or (uncaptioned and best[0][1] > 0)
            ):
                break
        if best is None:
            out.reason = "object not found"
            return None
        return self._grasp(env, best[1], out)

    def _receptacle_of(self, env: PrsEnv, o: SeenObject) -> str | None:
        cell = self._cell_of(env, o.position)
        if cell is None:
            return None
        floor = self.station.floors[env.floor]
        best = None
        for i in range(cell[0] - 2, cell[0] + 3):
            for j in range(cell[1] - 2, cell[1] + 3):
                if floor.inside((i, j)) and floor.receptacle_of[i, j] >= 0:
                    d = abs(i - cell[0]) + abs(j - cell[1])
                    if best is None or d < best[0]:
                        best = (d, self.station.receptacles[int(floor.receptacle_of[i, j])].name)
        return best[1] if best else None

    def _grasp(self, env: PrsEnv, o: SeenObject, out: Outcome) -> SeenObject | None:
        cell = self._cell_of(env, o.position)
        if cell is None:
            out.reason = "object off the robot's floor"
            return None
        room = self.station.room_at(env.floor, cell)
        stand = self.stand_near(env, (cell[0], cell[0], cell[1], cell[1]), room.id if room else None)
        if stand is None or not self._go(env, stand, out):
            out.reason = "no free cell next to the object"
            return None
        here = env.world(env.cell)
        if math.dist((here[0], here[2]), (o.position[0], o.position[2])) > REACH_M:
            out.reason = "object out of reach from every free cell"
            return None
        try:
            env.observe()
            env.grasp(o.name)
        except ActionError as exc:
            out.reason = f"grasp refused: {exc}"
            return None
        out.grasped = o.name
        return o

    def _person_rooms(self, env: PrsEnv, parsed: ParsedRequest, person: Person | None) -> list[Room]:
        st = self.station
        hour, minute = env.request.time.hour, env.request.time.minute
        order: list[str] = []

        def add(ids: list[str]) -> None:
            order.extend(i for i in ids if i not in order)

        def sched(h: int) -> list[str]:
            if person is None:
                return []
            slots = list(person.slots_at(h))
            if slots:  # the slot of this part of the hour first
                k = min(len(slots) - 1, minute * len(slots) // 60) if h == hour else 0
                slots = [slots[k], *slots[:k], *slots[k + 1 :]]
            rooms = [st.room_of_location(s.location) for s in slots]
            return [r.id for r in rooms if r is not None]

        own: list[str] = []
        if person is not None:
            for key in ("room", "office"):
                code = person.information.get(key)
                r = st.room_of_location(code) if isinstance(code, str) else None
                if r is not None:
                    own.append(r.id)
        hints: list[str] = []
        for head in parsed.dest_heads:
            ids = [
                r.id
                for r in st.rooms
                if tuple(t for t in normalise(r.name).split() if not t.isdigit() and t != "room") == head
            ]
            mine = [i for i in ids if i in own]
            hints += mine if mine else ids
        now = sched(hour)
        add([i for i in hints if i in now])
        add(now)
        add(hints)
        add([n for r in now for n in self.neighbours.get(r, [])])  # through a doorway
        add(sched(hour + 1) + sched(hour - 1))
        add(own)
        here = env.cell
        rest = sorted(
            (r for r in st.rooms if r.floor == env.floor and r.id not in order),
            key=lambda r: math.dist(((r.box[0] + r.box[1]) / 2, (r.box[2] + r.box[3]) / 2), here),
        )
        return [st.room(i) for i in order if st.room(i).floor == env.floor] + rest

    def _match_person(
        self, seen: Observation, person: Person | None, parsed: ParsedRequest
    ) -> SeenPerson | None:
        if person is not None:
            want = " ".join(person.character.split())
            for p in seen.people:
                if " ".join(p.appearance.split()) == want:
                    return p
            return None
        text = set(words(" ".join(parsed.sentences))) - STOP
        scored = [(len(set(words(p.appearance)) - STOP & text), p) for p in seen.people]
        scored = [s for s in scored if s[0] >= 2]
        return max(scored, key=lambda s: s[0])[1] if scored else None

    def _deliver(self, env: PrsEnv, parsed: ParsedRequest, person: Person | None, out: Outcome) -> None:
        for room in self._person_rooms(env, parsed, person):
            if env.done:
                break
            for view in self._viewpoints(env, room):
                if env.done or not self._go(env, view, out):
                    break
                found = self._match_person(env.observe(), person, parsed)
                if found is None:
                    continue
                out.person_seen = True
                cell = self._cell_of(env, found.position)
                if cell is None:
                    continue
                stand = self.stand_near(env, (cell[0], cell[0], cell[1], cell[1]), room.id)
                if stand is None or env.done or not self._go(env, stand, out):
                    continue
                if env.done:
                    break
                env.hand_over(found.handle)
                out.delivered = True
                out.reason = ""
                return
        out.reason = "time limit" if env.done else "person not found"
        if not env.done:
            env.give_up(out.reason)

    def _viewpoints(self, env: PrsEnv, room: Room) -> list[Cell]:
        """Standing cells covering a room: the free cell nearest its centre, then -- only when the map says
        that cell does not see ``COVERAGE`` of the room's free cells -- the free cell farthest from it."""
        i0, i1, j0, j1 = room.box
        centre = ((i0 + i1) // 2, (j0 + j1) // 2)
        first = self.stand_near(env, (centre[0], centre[0], centre[1], centre[1]), room.id)
        if first is None:
            return []
        floor = self.station.floors[env.floor]
        k = next(n for n, r in enumerate(self.station.rooms) if r.id == room.id)
        comp = self._components[env.floor]
        cells = np.argwhere(floor.walkable & (floor.room_of == k) & (comp == comp[env.cell]))
        blocked = floor.grid == 0
        reach = SENSOR_RANGE_M / env.cell_size
        seen = sum(
            math.dist(first, c) <= reach and line_of_sight(blocked, first, (int(c[0]), int(c[1])))
            for c in cells
        )
        if seen >= COVERAGE * len(cells):
            return [first]
        far = cells[int(np.argmax(((cells - np.array(first)) ** 2).sum(1)))]
        second = (int(far[0]), int(far[1]))
        return [first] if second == first else [first, second]
