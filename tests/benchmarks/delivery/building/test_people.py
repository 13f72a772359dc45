"""People: routines cover the day, actual days are deterministic per seed, locations are consistent."""

from __future__ import annotations

import itertools

from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.people import DAY_END, DAY_START, PeopleClock, daily_schedule


def test_profiles(shipped: Building) -> None:
    names = {p.name for p in shipped.people}
    assert len(names) == len(shipped.people) >= 10
    for p in shipped.people:
        assert p.routine[0].start == DAY_START and p.routine[-1].end == DAY_END
        assert any(s.room == p.home_room for s in p.routine)
        assert p.appearance.garment and p.appearance.color and p.role


def test_schedule_deterministic_per_seed(shipped: Building) -> None:
    p = shipped.people[0]
    assert daily_schedule(shipped, p, 5) == daily_schedule(shipped, p, 5)
    days = {daily_schedule(shipped, p, s) for s in range(10)}
    assert len(days) > 1  # seeds do change the day
    for s in range(10):
        day = daily_schedule(shipped, p, s)
        assert all(a.end == b.start for a, b in itertools.pairwise(day))
        assert day[0].start == DAY_START and day[-1].end == DAY_END


def test_locations(shipped: Building) -> None:
    bmap = BuildingMap(shipped)
    a = PeopleClock(shipped, 9, bmap)
    b = PeopleClock(shipped, 9, bmap)
    for p in shipped.people:
        for t in range(DAY_START, DAY_END, 997):
            where = a.location(p.id, t)
            assert where == b.location(p.id, t)
            slot = a.slot_at(p.id, t)
            assert slot is not None
            if a.in_transit(p.id, t):
                assert where is None or bmap.is_walkable(where)  # None: riding the elevator
                continue
            assert where is not None and bmap.room_at(where) == slot.room
            assert bmap.is_walkable(where)
            assert p.id in a.people_in(slot.room, t)
        assert a.location(p.id, DAY_START - 1) is None  # not in the building before the day starts


def test_people_move_within_a_slot(shipped: Building) -> None:
    bmap = BuildingMap(shipped)
    clock = PeopleClock(shipped, 2, bmap)
    pid = shipped.people[0].id
    slot = max(clock.schedule(pid), key=lambda s: s.end - s.start)
    spots = {clock.location(pid, t) for t in range(slot.start, slot.end, 180)}
    assert len(spots) > 1


def test_walks_between_rooms(shipped: Building) -> None:
    bmap = BuildingMap(shipped)
    clock = PeopleClock(shipped, 4, bmap)
    walks = 0
    for p in shipped.people:
        day = clock.schedule(p.id)
        for prev, slot in itertools.pairwise(day):
            if prev.room == slot.room:
                continue
            walks += 1
            before = clock.location(p.id, slot.start - 1)
            assert clock.in_transit(p.id, slot.start)
            assert clock.location(p.id, slot.start) == before  # sets off from where they stood
            t = slot.start
            last = before
            while clock.in_transit(p.id, t):
                here = clock.location(p.id, t)
                if here is not None and last is not None and here[0] == last[0]:
                    assert max(abs(here[1] - last[1]), abs(here[2] - last[2])) <= 4  # <= 1.2 m/s * 1 s
                last = here
                t += 1
            assert t - slot.start < 600
            assert bmap.room_at(clock.location(p.id, t)) == slot.room
    assert walks > 20
