"""PRS's delivery scoring rules, written from its ``eval.py`` (read, not copied).

Per task: grasp = 1 for the exact target object, 0.5 when the held object's name contains the target's
type; human found = 1 within 3 m of the person (world distance in x, y, z), 0.5 within 5 m; deliver =
found x grasp. A task succeeds with the exact object delivered to the person found within 3 m (what PRS's
in-simulator scorer, ``delivery_task_score``, sums to 4 with ``object_find`` = 1 for the exact object).
Aggregates follow ``eval.py``: tasks longer than 10 minutes are skipped (count as failures); rates divide
by the number of annotated tasks; the time used divides by the number of submitted tasks.

Note: the published ``eval.py`` never sets ``object_find``, so its own ``Task SR`` is 0 for every
submission (its per-task sum is at most 3, and it counts ``int(sum / 4)``); see docs/delivery.md.
"""

from __future__ import annotations

import math
from datetime import datetime

from gsr.benchmarks.delivery.prs_tasks import PrsTruth

TIME_LIMIT_MIN = 10.0


def _dist(a: dict, b: tuple[float, float, float]) -> float:
    return math.sqrt((a["x"] - b[0]) ** 2 + (a["y"] - b[1]) ** 2 + (a["z"] - b[2]) ** 2)


def score_entry(entry: dict, truth: PrsTruth) -> dict:
    """One submission entry scored against the task's truth."""
    minutes = (
        datetime.fromisoformat(entry["end_time"]) - datetime.fromisoformat(entry["start_time"])
    ).total_seconds() / 60
    held = entry.get("agent_object_name")
    grasp = 0.0
    if held is not None:
        if held == truth.target_object_name:
            grasp = 1.0
        elif truth.target_object_type in held:
            grasp = 0.5
    d = _dist(entry["agent_position"], truth.npc_position)
    human = 1.0 if d < 3 else 0.5 if d < 5 else 0.0
    deliver = human * grasp
    success = grasp == 1.0 and human == 1.0 and minutes <= TIME_LIMIT_MIN
    return {
        "grasp": grasp,
        "human_found": human,
        "deliver": deliver,
        "minutes": minutes,
        "success": success,
        "distance_m": d,
    }


def aggregate(scores: list[dict], annotated: int) -> dict:
    """Task SR, Object Manipulation SR, Human Search SR and Time Used as PRS aggregates them."""
    within = [s for s in scores if s["minutes"] <= TIME_LIMIT_MIN]
    n = float(annotated)
    return {
        "Task SR": sum(s["success"] for s in within) / n,
        "Object Manipulation SR": sum(s["grasp"] for s in within) / n,
        "Human Search SR": sum(s["human_found"] for s in within) / n,
        "Time Used": sum(s["minutes"] for s in within) / max(1, len(scores)),
        "tasks": len(scores),
        "annotated": annotated,
    }
