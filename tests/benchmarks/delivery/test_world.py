"""Scoring rules of the simulated world: 3 m / 5 m radii, the 8-minute limit, one object in hand."""

from __future__ import annotations

import pytest
from gsr.benchmarks.delivery.tasks import generate_tasks
from gsr.benchmarks.delivery.world import PICK_SECONDS, DeliveryWorld


@pytest.fixture
def world(shipped, bmap) -> DeliveryWorld:
    task = generate_tasks(shipped, "val", limit=1)[0]
    return DeliveryWorld(shipped, bmap, task)


def _cell_at_distance(world: DeliveryWorld, lo: float, hi: float):
    """A walkable cell whose walking distance to the target person is in (lo, hi] right now."""
    where = world.clock.location(world.task.person, world.time)
    room = world.bmap.room_at(where)
    for cell in world.bmap.free_cells(room):
        place = (where[0], *cell)
        if lo < world.bmap.distance(place, where) <= hi:
            return place
    pytest.skip("no cell at that distance in this room")


def _hold_target(world: DeliveryWorld) -> None:
    world.held = world.task.item
    del world.item_at[world.task.item]


def test_handover_within_3m_succeeds(world) -> None:
    _hold_target(world)
    world.robot = _cell_at_distance(world, 1.0, 2.5)
    assert world.handover(world.task.person)
    assert world.done and world.log.delivered
    assert world.log.person_within_3m and world.log.person_within_5m


def test_handover_between_3_and_5m_fails_but_counts_as_near(world) -> None:
    _hold_target(world)
    world.robot = _cell_at_distance(world, 3.2, 4.9)
    world._note_person()
    assert not world.handover(world.task.person)
    assert not world.log.delivered and not world.done
    assert world.log.person_within_5m and not world.log.person_within_3m


def test_wrong_object_is_not_a_delivery(world, shipped) -> None:
    other = next(it.id for it in shipped.items if it.id != world.task.item)
    world.held = other
    world.robot = _cell_at_distance(world, 0.0, 2.0)
    assert world.handover(world.task.person)
    assert world.done and not world.log.delivered


def test_time_limit(world) -> None:
    _hold_target(world)
    world.time = world.t0 + world.task.time_limit - 1.0  # one second left, a handover takes five
    world.robot = _cell_at_distance(world, 0.0, 2.0)
    assert not world.handover(world.task.person)
    assert world.done and world.log.timed_out and not world.log.delivered
    assert world.elapsed == world.task.time_limit


def test_pick_rules(world, shipped) -> None:
    item = shipped.items[0]
    rec = shipped.receptacle(item.receptacle)
    assert not world.pick(item.id)  # not standing at the receptacle
    world.robot = (shipped.room(rec.room).floor, *rec.access)
    if rec.closed:
        assert not world.pick(item.id)  # must open it first
        assert world.open(rec.id)
    t = world.time
    for _ in range(10):
        if world.pick(item.id):
            break
    assert world.held == item.id
    assert world.time >= t + PICK_SECONDS
    second = next(it for it in shipped.items if it.receptacle == item.receptacle and it.id != item.id)
    assert not world.pick(second.id)  # one object at a time
    assert world.place(rec.id) and world.held is None


def test_look_shows_only_open_receptacles(world, shipped) -> None:
    rec = next(
        r for r in shipped.receptacles if r.closed and any(it.receptacle == r.id for it in shipped.items)
    )
    world.robot = (shipped.room(rec.room).floor, *rec.access)
    inside = {it.id for it in shipped.items if it.receptacle == rec.id}
    assert not inside & set(world.look().items)
    world.open(rec.id)
    assert inside <= set(world.look().items)


def test_success_is_a_state_condition(world) -> None:
    _hold_target(world)
    world.robot = _cell_at_distance(world, 0.5, 2.5)
    world._note_person()  # what every action does when it ends: no handover needed
    assert world.done and world.log.delivered
    assert not world.look().items  # the episode is over: actions do nothing


def test_being_near_without_the_object_is_not_success(world) -> None:
    world.robot = _cell_at_distance(world, 0.0, 2.0)
    world._note_person()
    assert world.log.person_within_3m and not world.done and not world.log.delivered
