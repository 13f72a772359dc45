"""Implementations of the ``gsr delivery ...`` commands (the typer layer in gsr/cli.py stays thin).

Each function prints its output and returns the exit code: 0 success, 1 bad input (one-line message).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from gsr.benchmarks.delivery.agent import BaselineAgent
from gsr.benchmarks.delivery.building.checks import building_problems
from gsr.benchmarks.delivery.building.generator import generate_building
from gsr.benchmarks.delivery.building.model import Building, save_building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.people import PeopleClock
from gsr.benchmarks.delivery.metrics import breakdown, breakdown_table, score_episode, summary_table
from gsr.benchmarks.delivery.run import AGENTS, checked_building, parser_for, run_split, run_tasks
from gsr.benchmarks.delivery.tasks import SPLITS, generate_tasks, load_tasks, make_task, save_tasks
from gsr.benchmarks.delivery.world import DeliveryWorld

from gsr.errors import GSRError
from gsr.io import write_text_atomic


def _err(message: str) -> int:
    print(f"error: {message}", file=sys.stderr)
    return 1


def _building(path: Path | None) -> Building:
    """The shipped building, or a user's file checked against the building invariants."""
    return checked_building(path)


def generate_building_command(seed: int, out: Path, floors: int, people: int, name: str | None) -> int:
    """Generate a building, check its invariants, write it atomically and print a summary."""
    try:
        building = generate_building(seed, floors=floors, people=people, name=name)
    except ValueError as exc:
        return _err(str(exc))
    problems = building_problems(building)
    if problems:
        return _err(f"generated building violates {len(problems)} invariants: {problems[0]}")
    try:
        save_building(building, out)
    except OSError as exc:
        return _err(f"{out}: cannot write: {exc.strerror}")
    print(describe(building) + f"\nwrote {out}")
    return 0


def describe(building: Building) -> str:
    """A few lines about a building: floors, rooms, receptacles, objects, people."""
    lines = [f"{building.name} (seed {building.seed}): {len(building.floors)} floors"]
    for f in building.floors:
        rooms = [r.name for r in building.rooms if r.floor == f.level and r.kind != "corridor"]
        lines.append(f"  {f.name} ({f.shape[1]}x{f.shape[0]} cells): {', '.join(rooms)}")
    kinds = {it.category for it in building.items}
    lines.append(
        f"  {sum(r.kind != 'corridor' for r in building.rooms)} rooms, {len(building.receptacles)} receptacles, "
        f"{len(building.items)} objects of {len(kinds)} types, {len(building.people)} people"
    )
    return "\n".join(lines)


def tasks_command(split: str, building_path: Path | None, limit: int | None, out: Path | None) -> int:
    """Generate a split's tasks; print them (id, instruction) or write JSON Lines."""
    try:
        building = _building(building_path)
        tasks = generate_tasks(building, split, limit)
    except (GSRError, ValueError) as exc:
        return _err(str(exc))
    if out is not None:
        try:
            save_tasks(tasks, out)
        except OSError as exc:
            return _err(f"{out}: cannot write: {exc.strerror}")
        print(f"wrote {len(tasks)} {split} tasks to {out}")
        return 0
    for t in tasks:
        print(f"{t.id}\t{t.instruction}")
    return 0


def run_command(
    split: str,
    building_path: Path | None,
    tasks_path: Path | None,
    limit: int | None,
    as_json: bool,
    out: Path | None,
    agent: str = "baseline",
    by_kind: bool = False,
) -> int:
    """Run the baseline on a split (or a tasks file) and print the PRS-style table or JSON summary."""
    try:
        building = _building(building_path)
        if tasks_path is not None:
            tasks = load_tasks(tasks_path)[:limit] if limit else load_tasks(tasks_path)
            if not tasks:
                return _err(f"{tasks_path}: no tasks")
            result = run_tasks(building, tasks, tasks_path.stem, agent)
        else:
            result = run_split(building, split, limit, agent)
    except (GSRError, ValueError) as exc:
        return _err(str(exc))
    rows = breakdown(result.tasks, result.results)
    if out is not None:
        body = json.dumps(
            {
                "agent": agent,
                "summary": result.summary.model_dump(),
                "breakdown": rows,
                "episodes": [r.model_dump() for r in result.results],
            },
            indent=1,
        )
        try:
            write_text_atomic(out, body + "\n")
        except OSError as exc:
            return _err(f"{out}: cannot write: {exc.strerror}")
    if as_json:
        data = result.summary.model_dump()
        if by_kind:
            data["breakdown"] = rows
        print(json.dumps(data, indent=2))
    else:
        print(summary_table(result.summary), end="")
        if by_kind:
            print("\n" + breakdown_table(rows), end="")
    return 0


def schedule_command(person: str, seed: int, building_path: Path | None) -> int:
    """Print a person's routine and their actual day under a world seed."""
    try:
        building = _building(building_path)
        p = building.person(person.lower())
    except (GSRError, KeyError) as exc:
        return _err(str(exc).strip("'\""))
    clock = PeopleClock(building, seed, BuildingMap(building))

    def hhmm(t: int) -> str:
        return f"{t // 3600:02d}:{t % 3600 // 60:02d}"

    a = p.appearance
    look = f"{a.gender}, {a.color} {a.garment}, {a.hair}" + (", glasses" if a.glasses else "")
    print(f"{p.name} ({p.role}; {look}); home room {building.room(p.home_room).name}")
    print("routine:")
    for s in p.routine:
        print(f"  {hhmm(s.start)}-{hhmm(s.end)}  {building.room(s.room).name:<18} {s.activity}")
    print(f"actual day (world seed {seed}):")
    for s in clock.schedule(p.id):
        print(f"  {hhmm(s.start)}-{hhmm(s.end)}  {building.room(s.room).name:<18} {s.activity}")
    return 0


def parse_clock(text: str) -> int:
    """``HH:MM`` (or plain seconds) to seconds since midnight; ValueError with the accepted forms."""
    if text.isdigit():
        return int(text)
    hh, sep, mm = text.partition(":")
    if not sep or not (hh.isdigit() and mm.isdigit()) or int(hh) > 23 or int(mm) > 59:
        raise ValueError(f"bad time {text!r}: expected HH:MM (e.g. 12:30) or seconds since midnight")
    return int(hh) * 3600 + int(mm) * 60


def map_command(floor: int, at: str, seed: int, building_path: Path | None) -> int:
    """Print a floor's grid with everyone on it at a time of day (first letter of their name)."""
    try:
        t = parse_clock(at)
        building = _building(building_path)
        grid = [list(row) for row in building.floor(floor).grid]
    except (GSRError, KeyError, ValueError) as exc:
        return _err(str(exc).strip("'\""))
    clock = PeopleClock(building, seed, BuildingMap(building))
    legend = []
    for p in building.people:
        where = clock.location(p.id, t)
        if where is None or where[0] != floor:
            continue
        grid[where[1]][where[2]] = p.name[0]
        room = clock.bmap.room_at(where)
        place = building.room(room).name if room else "a doorway"
        legend.append(f"{p.name[0]} = {p.name} ({p.role}) in {place}")
    print(f"{building.floor(floor).name} at {t // 3600:02d}:{t % 3600 // 60:02d}, world seed {seed}")
    print("\n".join("".join(row) for row in grid))
    print("\n".join(legend) if legend else "nobody on this floor")
    return 0


def episode_command(task_id: str, building_path: Path | None, agent: str) -> int:
    """Run one task (``test-0004``) and print what the agent understood and did, second by second."""
    split, _, number = task_id.partition("-")
    if split not in SPLITS or not number.isdigit() or int(number) >= SPLITS[split][1]:
        return _err(
            f"bad task id {task_id!r}: expected SPLIT-NNNN, e.g. test-0004 (splits: {', '.join(SPLITS)})"
        )
    if agent not in AGENTS:
        return _err(f"unknown agent {agent!r} (known: {', '.join(AGENTS)})")

    try:
        building = _building(building_path)
    except GSRError as exc:
        return _err(str(exc))
    bmap = BuildingMap(building)
    task = make_task(building, bmap, split, int(number), SPLITS[split][0])
    world = DeliveryWorld(building, bmap, task)
    trace = BaselineAgent(building, bmap, parser_for(building), use_routines=agent == "baseline").run(world)
    result = score_episode(task, world, trace)
    t = task.start_time
    print(f"{task.id} at {t // 3600:02d}:{t % 3600 // 60:02d}: {task.instruction}")
    print(f"  target: {task.item} -> {task.person}")
    print(f"  parsed: {trace.parsed.model_dump(exclude_none=True) if trace.parsed else trace.parse_error}")
    for elapsed, text in world.log.events:
        print(f"  {elapsed:6.1f} s  {text}")
    verdict = "SUCCESS" if result.success else ("TIMEOUT" if result.timed_out else "FAILED")
    print(
        f"  {verdict} in {result.time:.1f} s: object found {result.object_found}, grasped {result.grasped}, "
        f"within 5 m {result.person_within_5m}, within 3 m {result.person_within_3m}"
    )
    return 0
