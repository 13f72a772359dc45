"""Delivery tasks: who needs what, where it is, and the instruction that says so (seeded, per split).

A task picks a person and something they need (their role's needs or common ones) that the building
stocks, then a referring expression that singles out one object (colour / receptacle / room, as much as
needed) and one person (name, role or look), renders it with a template and records the ground-truth
``Reference`` the parser should recover.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from gsr.benchmarks.delivery.building.catalog import COMMON_NEEDS, ROLES
from gsr.benchmarks.delivery.building.model import Building, Item, Person
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.reference import ObjectRef, PersonRef, Reference
from pydantic import BaseModel, ConfigDict, ValidationError

from gsr.errors import GSRError
from gsr.io import read_text, write_text_atomic
from gsr.scene_graph import format_validation_error

SPLITS: dict[str, tuple[int, int]] = {"train": (11, 2000), "val": (12, 200), "test": (13, 1000)}
TIME_LIMIT = 480.0  # seconds of simulated time per episode (8 minutes)
DAY_WINDOW = (8 * 3600, 19 * 3600 + 1800)


class DeliveryTask(BaseModel):
    """One episode: the instruction, its ground truth, the start state and the world seed."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    id: str
    instruction: str
    item: str  # id of the object to deliver
    person: str  # id of the recipient
    reference: Reference  # what the instruction mentions (parser ground truth)
    start_time: int  # seconds since midnight
    start: tuple[int, int, int]  # robot (floor, row, col)
    world_seed: int
    time_limit: float = TIME_LIMIT


def room_text(building: Building, room_id: str) -> str:
    """How an instruction names a room: its number as is (``room 204``), else with an article."""
    name = building.room(room_id).name
    return name if any(ch.isdigit() for ch in name) else f"the {name}"


def object_phrase(building: Building, ref: ObjectRef, names: dict[str, str], rng: np.random.Generator) -> str:
    """The object's phrase in an instruction: colour and name, then its receptacle and room if given."""
    text = "the " + (f"{ref.color} " if ref.color else "") + names[ref.category]
    if ref.receptacle:
        rec_name = ref.receptacle.replace("_", " ")
        lead = ["from", "that is on" if not _closed(building, ref) else "that is in"][int(rng.random() < 0.3)]
        text += f" {lead} the {rec_name}"
        if ref.room:
            text += f" in {room_text(building, ref.room)}"
    elif ref.room:
        text += f" from {room_text(building, ref.room)}"
    return text


def _closed(building: Building, ref: ObjectRef) -> bool:
    return any(r.category == ref.receptacle and r.relation == "in" for r in building.receptacles)


def person_phrase(building: Building, ref: PersonRef) -> str:
    """The recipient's phrase in an instruction, from the reference's name or description."""
    parts = []
    if ref.name:
        parts.append(building.person(ref.name).name)
    if ref.gender or ref.role:
        desc = f"the {ref.role or ref.gender}"
        if ref.garment:
            desc += f" in the {ref.color} {ref.garment}"
        if ref.hair:
            desc += f" with {ref.hair}"
        if ref.glasses:
            desc += " with glasses"
        parts.append(desc)
    text = ", ".join(parts)
    if ref.room:
        text += f" in {room_text(building, ref.room)}"
    return text


def _matches(item: Item, ref: ObjectRef, rec_room: dict[str, str], rec_cat: dict[str, str]) -> bool:
    return (
        item.category == ref.category
        and (ref.color is None or item.color == ref.color)
        and (ref.receptacle is None or rec_cat[item.receptacle] == ref.receptacle)
        and (ref.room is None or rec_room[item.receptacle] == ref.room)
    )


def _person_matches(p: Person, ref: PersonRef) -> bool:
    a = p.appearance
    return (
        (ref.name is None or p.id == ref.name)
        and (ref.role is None or p.role == ref.role)
        and (ref.gender is None or a.gender == ref.gender)
        and (ref.garment is None or (a.garment == ref.garment and a.color == ref.color))
        and (ref.hair is None or a.hair == ref.hair)
        and (ref.glasses is None or a.glasses == ref.glasses)
    )


def _object_ref(building: Building, item: Item, rng: np.random.Generator) -> ObjectRef | None:
    """The shortest unambiguous description of ``item``, starting from a randomly chosen detail level."""
    rec = building.receptacle(item.receptacle)
    rec_room = {r.id: r.room for r in building.receptacles}
    rec_cat = {r.id: r.category for r in building.receptacles}
    levels = [
        ObjectRef(category=item.category, color=item.color),
        ObjectRef(category=item.category, color=item.color, room=rec.room),
        ObjectRef(category=item.category, receptacle=rec.category, room=rec.room),
        ObjectRef(category=item.category, color=item.color, receptacle=rec.category, room=rec.room),
    ]
    first = int(rng.choice(4, p=[0.15, 0.2, 0.15, 0.5]))
    for ref in levels[first:]:
        if sum(_matches(it, ref, rec_room, rec_cat) for it in building.items) == 1:
            return ref
    return None


def _person_ref(building: Building, p: Person, hint_room: str | None, rng: np.random.Generator) -> PersonRef:
    a = p.appearance
    wears = {"gender": a.gender, "garment": a.garment, "color": a.color}
    options = [
        PersonRef(name=p.id),
        PersonRef(name=p.id, **wears),
        PersonRef(name=p.id, role=p.role),
        PersonRef(role=p.role),
        PersonRef(**wears),
        PersonRef(gender=a.gender, hair=a.hair),
    ]
    weights = np.array([0.25, 0.3, 0.15, 0.1, 0.12, 0.08])
    for i in rng.choice(len(options), size=len(options), replace=False, p=weights):
        ref = options[int(i)]
        if sum(_person_matches(q, ref) for q in building.people) == 1:
            return ref.model_copy(update={"room": hint_room})
    return PersonRef(name=p.id, room=hint_room)


#: Instruction sentences; ``{obj}`` and ``{person}`` take the phrases above.
TEMPLATES = (
    "Fetch {obj} and deliver it to {person}.",
    "Get {obj} and bring it to {person}.",
    "Bring {obj} to {person}.",
    "Please take {obj} to {person}.",
    "Grab {obj} and hand it to {person}.",
    "Can you bring {person} {obj}?",
    "{person} needs {bare}. It is {where}.",
    "{person} asked for {bare}; it is {where}.",
)


def make_task(building: Building, bmap: BuildingMap, split: str, index: int, seed: int) -> DeliveryTask:
    """Task number ``index`` of a split (deterministic in building seed, split seed and index)."""
    rng = np.random.default_rng([building.seed, seed, index])
    names = {it.category: it.name for it in building.items}
    for _ in range(100):
        person = building.people[int(rng.integers(len(building.people)))]
        needs = [c for c in (*ROLES[person.role].needs, *COMMON_NEEDS) if c in names]
        category = needs[int(rng.integers(len(needs)))] if needs else None
        pool = [it for it in building.items if it.category == category] or list(building.items)
        item = pool[int(rng.integers(len(pool)))]
        oref = _object_ref(building, item, rng)
        if oref is not None:
            break
    else:  # pragma: no cover - a building where nothing can be singled out
        raise ValueError(f"building {building.name}: no uniquely describable object for task {index}")
    start_time = int(rng.integers(*DAY_WINDOW))
    routine_room = next(s.room for s in person.routine if s.start <= start_time < s.end)
    pref = _person_ref(building, person, routine_room if rng.random() < 0.5 else None, rng)
    template = TEMPLATES[int(rng.integers(len(TEMPLATES)))]
    if "{where}" in template and oref.receptacle is None:
        template = TEMPLATES[0]
    obj = object_phrase(building, oref, names, rng)
    bare = "the " + (f"{oref.color} " if oref.color else "") + names[oref.category]
    where = ""
    if oref.receptacle:
        rel = building.receptacle(item.receptacle).relation
        where = f"{rel} the {oref.receptacle.replace('_', ' ')}" + (
            f" in {room_text(building, oref.room)}" if oref.room else ""
        )
    text = template.format(obj=obj, person=person_phrase(building, pref), bare=bare, where=where)
    text = text[0].upper() + text[1:]
    rooms = [r for r in building.rooms if r.kind not in ("bedroom",)]
    room = rooms[int(rng.integers(len(rooms)))]
    cells = bmap.free_cells(room.id)
    cell = cells[int(rng.integers(len(cells)))]
    return DeliveryTask(
        id=f"{split}-{index:04d}",
        instruction=text,
        item=item.id,
        person=person.id,
        reference=Reference(object=oref, person=pref),
        start_time=start_time,
        start=(room.floor, *cell),
        world_seed=int(rng.integers(2**31)),
    )


def generate_tasks(building: Building, split: str = "test", limit: int | None = None) -> list[DeliveryTask]:
    """The tasks of a split (``train`` 2000, ``val`` 200, ``test`` 1000), or its first ``limit``."""
    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r} (known: {', '.join(SPLITS)})")
    seed, count = SPLITS[split]
    n = count if limit is None else min(limit, count)
    bmap = BuildingMap(building)
    return [make_task(building, bmap, split, i, seed) for i in range(n)]


def save_tasks(tasks: list[DeliveryTask], path: str | Path) -> None:
    """Write tasks as JSON Lines, atomically."""
    write_text_atomic(Path(path), "".join(t.model_dump_json() + "\n" for t in tasks))


def load_tasks(path: str | Path) -> list[DeliveryTask]:
    """Read JSON Lines tasks (errors name the file and line)."""
    out = []
    for n, line in enumerate(read_text(path).splitlines(), 1):
        if not line.strip():
            continue
        try:
            out.append(DeliveryTask.model_validate(json.loads(line)))
        except json.JSONDecodeError as exc:
            raise GSRError(f"{path}:{n}: invalid JSON: {exc.msg}") from None
        except ValidationError as exc:
            raise GSRError(f"{path}:{n}: invalid task: {format_validation_error(exc)}") from None
    return out
