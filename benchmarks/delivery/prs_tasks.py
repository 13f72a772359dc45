"""PRS delivery task files: what the robot is told, what only the evaluator knows, the object inventory.

A PRS task file is a JSON object keyed by task id. Each task splits in two here:

- ``PrsRequest`` — what PRS's ``delivery_task_import`` hands a robot: the instruction (the two directive
  sentences joined as PRS joins them), the recipient's description with their name, the request time;
- ``PrsTruth`` — the evaluator's fields: target object name/type/position, person id/position/action.

The object inventory of a run is every object any task of the file names, placed at its position, with
the floor, cell, room and receptacle derived from the station's geometry.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from gsr.benchmarks.delivery.building.prs_files import PrsDataError, need, read_json
from gsr.benchmarks.delivery.building.prs_station import PlacedObject, Station, place_object

Point = tuple[float, float, float]


@dataclass(frozen=True)
class PrsRequest:
    """What the robot is given: instruction, recipient description (with name), the request time."""

    task_id: str
    instruction: str
    npc_information: str
    time: datetime


@dataclass(frozen=True)
class PrsTruth:
    """The evaluator's side of a task; never handed to the agent."""

    npc_id: int
    npc_name: str
    npc_position: Point
    npc_action: str
    target_object_name: str
    target_object_type: str
    target_object_pos: Point


@dataclass(frozen=True)
class PrsTask:
    """One task: the request and the truth."""

    request: PrsRequest
    truth: PrsTruth


def _point(value: object, path: Path, field: str) -> Point:
    if not isinstance(value, dict):
        raise PrsDataError(path, field, "expected {x, y, z}")
    out = []
    for axis in "xyz":
        v = need(value, axis, (int, float), path, f"{field} -> {axis}")
        out.append(float(v))
    return (out[0], out[1], out[2])


def instruction_of(directive: list[str]) -> str:
    """The instruction as PRS's ``delivery_task_import`` builds it: a fifth directive if present, else the
    first two sentences concatenated (PRS adds no space between them)."""
    return directive[4] if len(directive) > 4 else directive[0] + directive[1]


def load_tasks(path: str | Path, station: Station) -> list[PrsTask]:
    """Read and validate a PRS task file; a bad field -> ``PrsDataError`` naming the task and field."""
    path = Path(path)
    data = read_json(path)
    if not isinstance(data, dict) or not data:
        raise PrsDataError(path, None, "expected a non-empty JSON object of tasks keyed by task id")
    tasks = []
    for tid, t in data.items():
        if not isinstance(t, dict):
            raise PrsDataError(path, tid, "expected an object")
        directive = need(t, "directive", list, path, f"{tid} -> directive")
        if len(directive) < 2 or not all(isinstance(d, str) for d in directive):
            raise PrsDataError(path, f"{tid} -> directive", "expected at least two sentences (strings)")
        npc_id = need(t, "npc_id", int, path, f"{tid} -> npc_id")
        if npc_id not in station.people:
            raise PrsDataError(path, f"{tid} -> npc_id", f"no person {npc_id} in npc_data.json")
        name = need(t, "npc_name", str, path, f"{tid} -> npc_name")
        try:
            when = datetime.fromisoformat(need(t, "time", str, path, f"{tid} -> time"))
        except ValueError:
            raise PrsDataError(path, f"{tid} -> time", f"not an ISO time: {t['time']!r}") from None
        truth = PrsTruth(
            npc_id,
            name,
            _point(t.get("npc_position"), path, f"{tid} -> npc_position"),
            str(t.get("npc_action", "")),
            need(t, "target_object_name", str, path, f"{tid} -> target_object_name"),
            need(t, "target_object_type", str, path, f"{tid} -> target_object_type"),
            _point(t.get("target_object_pos"), path, f"{tid} -> target_object_pos"),
        )
        request = PrsRequest(str(tid), instruction_of(directive), station.people[npc_id].describe(name), when)
        tasks.append(PrsTask(request, truth))
    return tasks


def inventory(station: Station, tasks: list[PrsTask]) -> list[PlacedObject]:
    """Every object the tasks name, once, placed in the station."""
    seen: dict[str, PlacedObject] = {}
    for t in tasks:
        tr = t.truth
        if tr.target_object_name not in seen:
            seen[tr.target_object_name] = place_object(
                station, tr.target_object_name, tr.target_object_type, tr.target_object_pos
            )
    return list(seen.values())
