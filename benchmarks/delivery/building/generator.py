"""Seeded building generator: floors of rooms around a corridor, furniture, objects, people.

``generate_building(seed)`` with the defaults gives a three-floor building (public rooms on the ground
floor, offices and labs above, bedrooms on top); the same seed always gives the same building.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from gsr.benchmarks.delivery.building.catalog import RECEPTACLES, ROOM_KINDS
from gsr.benchmarks.delivery.building.furnish import place_receptacles, stock_items
from gsr.benchmarks.delivery.building.layout import floor_name, plan_floor
from gsr.benchmarks.delivery.building.model import Building, Connector, Door, Floor, Item, Receptacle, Room
from gsr.benchmarks.delivery.building.people import make_people

#: Room programmes per floor type (8 rooms each): ground, work floors, residential top floor.
GROUND = [
    "lobby",
    "kitchen",
    "dining_room",
    "living_room",
    "leisure_room",
    "gym",
    "medical_room",
    "laundry_room",
]
WORK = ["office", "office", "office", "office", "laboratory", "meeting_room", "library", "copy_room"]
HOME = ["bedroom", "bedroom", "bedroom", "bedroom", "bedroom", "lounge", "office", "laboratory"]


def _programme(floors: int) -> list[list[str]]:
    if floors == 1:
        return [GROUND]
    if floors == 2:
        return [GROUND, WORK[:4] + HOME[:4]]
    return [GROUND, *([WORK] * (floors - 2)), HOME]


def generate_building(
    seed: int,
    floors: int = 3,
    people: int = 12,
    width: int = 76,
    depth: int = 11,
    name: str | None = None,
) -> Building:
    """A building from ``seed``: ``floors`` storeys of 8 rooms, furnished and stocked, with ``people``."""
    if not 1 <= floors <= 6:
        raise ValueError(f"floors must be 1..6, got {floors}")
    if width < 50 or depth < 8:
        raise ValueError(f"floor too small (width {width} >= 50 and depth {depth} >= 8 cells needed)")
    rng = np.random.default_rng([seed, 0])
    programme = _programme(floors)
    kind_count = Counter(k for floor in programme for k in floor)
    unique_names = {k: ROOM_KINDS[k].name for k, n in kind_count.items() if n == 1}
    plans = []
    for level, kinds in enumerate(programme):
        shuffled = [kinds[int(i)] for i in rng.permutation(len(kinds))]
        plans.append(plan_floor(level, shuffled, width, depth, rng, unique_names))
    rooms: list[Room] = []
    doors: list[Door] = []
    receptacles: list[Receptacle] = []
    items: list[dict] = []
    counts: dict[str, int] = {}
    room_dicts: list[dict] = []
    for plan in plans:
        reserved = {plan.stairs_access, plan.elevator_access}
        for rd in plan.rooms:
            room_dicts.append(rd)
            rooms.append(
                Room(id=rd["id"], kind=rd["kind"], name=rd["name"], floor=plan.level, rect=rd["rect"])
            )
            placed = place_receptacles(plan.grid, rd, rng, reserved)
            per_cat: Counter[str] = Counter()
            for p in placed:
                per_cat[p["category"]] += 1
                number = rd["id"].rsplit("_", 1)[-1]
                p["id"] = f"{p['category']}_{number}" + (
                    f"_{per_cat[p['category']]}" if per_cat[p["category"]] > 1 else ""
                )
                rt = RECEPTACLES[p["category"]]
                receptacles.append(
                    Receptacle(
                        id=p["id"],
                        category=p["category"],
                        name=rt.name,
                        room=rd["id"],
                        relation=rt.relation,  # type: ignore[arg-type]
                        closed=rt.closed,
                        rect=p["rect"],
                        access=p["access"],
                    )
                )
            items += stock_items(placed, rd["kind"], rng, counts)
        doors += [Door(floor=plan.level, cell=d["cell"], rooms=d["rooms"]) for d in plan.doors]
    connectors = [
        Connector(
            id="stairs",
            kind="stairs",
            access={p.level: p.stairs_access for p in plans},
            seconds_per_floor=25.0,
        ),
        Connector(
            id="elevator",
            kind="elevator",
            access={p.level: p.elevator_access for p in plans},
            seconds_per_floor=6.0,
            call_seconds=20.0,
            door_seconds=4.0,
        ),
    ]
    return Building(
        name=name or f"building-{seed}",
        seed=seed,
        floors=tuple(
            Floor(level=p.level, name=floor_name(p.level), grid=tuple("".join(r) for r in p.grid))
            for p in plans
        ),
        rooms=tuple(rooms),
        doors=tuple(doors),
        receptacles=tuple(receptacles),
        items=tuple(Item(**it) for it in items),
        connectors=tuple(connectors),
        people=tuple(make_people(room_dicts, rng, people)),
    )
