"""A small synthetic PRS data folder (one floor, three rooms, two people) written by the tests themselves.

Layout of floor 0 (rows i, columns j), 24 x 40 cells, walls value 0:
- ``room0`` "kitchen room": i 1-10, j 1-18, a ``kitchen counter`` at i 2-3, j 5-9;
- ``room1`` "office space": i 1-10, j 21-38, a ``desk`` at i 7-8, j 30-33;
- ``room2`` "bed room 0": i 13-22, j 1-18, a ``table`` at i 20-21, j 3-5;
- a corridor (value 1) along row 11-12 joining doors at (10, 10), (10, 30), (13, 10).
Grid values are one below their tags, as in PRS's published maps. True transform: x = -5 + 0.3 i,
z = -3 + 0.3 j, floor height 0. Schedule codes are ``F1_KitchenRoom``, ``F1_OfficeSpaceRoom`` and
``F1_Bedroom_5`` (the last does not match the grid room's name: calibration must find it).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

X0, Z0, SCALE = -5.0, -3.0, 0.3
ROOMS = {"room0": ((1, 10), (1, 18)), "room1": ((1, 10), (21, 38)), "room2": ((13, 22), (1, 18))}
NAMES = {"room0": "kitchen room", "room1": "office space", "room2": "bed room 0"}
RECEPTACLES = {"room0": ("kitchen counter", (2, 3), (5, 9)), "room1": ("desk", (7, 8), (30, 33)),
               "room2": ("table", (20, 21), (3, 5))}  # fmt: skip


def world(i: float, j: float) -> tuple[float, float]:
    """The true world (x, z) of a cell."""
    return (X0 + SCALE * i, Z0 + SCALE * j)


def make_folder(root: Path) -> Path:
    """Write the folder under ``root``; returns its path."""
    folder = root / "prs"
    folder.mkdir()
    grid = np.zeros((24, 40), dtype=int)
    tags: dict[str, object] = {"0": "obstacles", "1": "accessible area"}
    value = 4  # tag keys; grid values are tag - 1
    for key, ((i0, i1), (j0, j1)) in ROOMS.items():
        tags[str(value)] = [key]
        grid[i0 : i1 + 1, j0 : j1 + 1] = value - 1
        value += 1
    for key, (name, (i0, i1), (j0, j1)) in RECEPTACLES.items():
        tags[str(value)] = [key, name]
        grid[i0 : i1 + 1, j0 : j1 + 1] = value - 1
        value += 1
    grid[11:13, 1:39] = 1
    for door in ((10, 10), (10, 30), (13, 10)):
        grid[door] = 1
    (folder / "semantic_map_0.txt").write_text("\n".join("\t".join(map(str, r)) for r in grid) + "\n")
    (folder / "semantic_map_tags.json").write_text(json.dumps({"0": tags}))
    (folder / "room_mapping.json").write_text(json.dumps({"0": NAMES}))
    (folder / "map_room_data.json").write_text(
        json.dumps({"0": {k: {"x": list(a), "y": list(b)} for k, (a, b) in ROOMS.items()}})
    )
    (folder / "map_receptacle_data.json").write_text(json.dumps({"0": {}}))
    (folder / "room_sampling_points.json").write_text("{}")
    people = [
        {"description": "I'm {name}, a cook. I wear a red apron.", "feature": "f", "character": "a man with a red apron",
         "information": {"id": 0, "room": "F1_Bedroom_5", "office": "F1_KitchenRoom"}},
        {"description": "I'm {name}, an analyst. I wear a green scarf.", "feature": "f",
         "character": "a woman with a green scarf",
         "information": {"id": 1, "room": "F1_Bedroom_5", "office": "F1_OfficeSpaceRoom"}},
    ]  # fmt: skip
    (folder / "npc_data.json").write_text(json.dumps({"npc": people, "names": []}))

    def day(pid: int) -> dict:
        out = {}
        for h in range(24):
            if h < 8 or h >= 22:
                loc = "F1_Bedroom_5"
            elif h % 2 == 0:
                loc = "F1_KitchenRoom" if pid == 0 else "F1_OfficeSpaceRoom"
            else:
                loc = "F1_OfficeSpaceRoom" if pid == 0 else "F1_KitchenRoom"
            out[str(h)] = [{"location": loc, "action": ["stand"]}]
        return {"id": pid, "schedule": out}

    (folder / "npc_schedule.json").write_text(json.dumps({"0": day(0), "1": day(1)}))
    (folder / "delivery_tasks_dev.json").write_text(json.dumps(tasks(40)))
    return folder


def tasks(n: int) -> dict:
    """``n`` tasks: the person stands in the room their schedule names; the object is on a receptacle."""
    rng = np.random.default_rng(3)
    objects = [
        ("RedApple_1", "RedApple", (2, 6)),
        ("BlueMug_1", "BlueMug", (7, 31)),
        ("BlueMug_2", "BlueMug", (20, 4)),
    ]
    room_of_code = {"F1_KitchenRoom": "room0", "F1_OfficeSpaceRoom": "room1", "F1_Bedroom_5": "room2"}
    out = {}
    for k in range(n):
        pid = k % 2
        hour = int(rng.integers(0, 24))
        if hour < 8 or hour >= 22:
            code = "F1_Bedroom_5"
        elif hour % 2 == 0:
            code = "F1_KitchenRoom" if pid == 0 else "F1_OfficeSpaceRoom"
        else:
            code = "F1_OfficeSpaceRoom" if pid == 0 else "F1_KitchenRoom"
        (i0, i1), (j0, j1) = ROOMS[room_of_code[code]]
        pi, pj = int(rng.integers(i0 + 1, i1)), int(rng.integers(j0 + 1, j1))
        while (
            (pi, pj) in {(2, 5), (2, 6)}
            or (2 <= pi <= 3 and 5 <= pj <= 9)
            or (7 <= pi <= 8 and 30 <= pj <= 33)
        ):
            pi, pj = int(rng.integers(i0 + 1, i1)), int(rng.integers(j0 + 1, j1))
        px, pz = world(pi, pj)
        name, typ, (oi, oj) = objects[k % 3]
        ox, oz = world(oi, oj)
        where = {"RedApple_1": "the kitchen counter in the kitchen", "BlueMug_1": "the desk in the office space",
                 "BlueMug_2": "the table in the bedroom"}[name]  # fmt: skip
        colour = "red apple" if typ == "RedApple" else ("blue mug with a white stripe" if name == "BlueMug_1"
                                                        else "plain blue mug")  # fmt: skip
        tid = f"t{k}"
        out[tid] = {
            "npc_name": "Ann" if pid else "Bob",
            "npc_id": pid,
            "time": f"2025-01-0{1 + k % 5}T{hour:02d}:{int(rng.integers(0, 60)):02d}:00",
            "npc_action": "stand",
            "npc_position": {"x": px, "y": 0.0, "z": pz},
            "target_object_name": name,
            "target_object_type": typ,
            "target_object_pos": {"x": ox, "y": 0.9, "z": oz},
            "directive": [
                f"Please fetch the {colour} from {where} and bring it to me.",
                f"Take the {colour} from {where} to {'Ann' if pid else 'Bob'}.",
            ],
            "task_id": tid,
        }
    return out
