"""PRS's delivery scoring rules, written from its ``eval.py`` (read, not copied).

Per task: grasp = 1 for the exact target object, 0.5 when the held object's name contains the target's
type; human found = 1 within 3 m of the person (world distance in x, y, z), 0.5 within 5 m; deliver =
found x grasp; object_find = 0 (``eval.py``'s ``delivery_task_score`` initialises it and never sets it);
PRS's per-task sum = grasp + object_find + deliver + human found.

Two Task SRs, reported side by side:

- ``Task SR``, the *simulator rule*: a task succeeds with the exact object delivered to the person found
  within 3 m in 10 minutes (what the in-simulator scorer sums to 4, with ``object_find`` = 1 for the exact
  object). This is the figure the project headlines.
- ``eval.py``'s own Task SR, ``sum(int(per-task sum / 4)) / annotated``: with ``object_find`` never set the
  per-task sum is at most 3, so it is **0 for every submission**. ``aggregate`` computes it the same way
  (``Task SR (eval.py)``, and the whole ``eval.py`` block), so the published scorer's output is reproduced
  exactly, its Task SR included; see docs/delivery.md.

Aggregates follow ``eval.py``: tasks longer than 10 minutes are skipped (count as failures); rates divide
by the number of annotated tasks; the time used divides by the number of submitted tasks.
"""

from __future__ import annotations

import math
from datetime import datetime

from gsr.benchmarks.delivery.prs_tasks import PrsTruth

TIME_LIMIT_MIN = 10.0
#: ``object_find`` as the published ``eval.py`` scores it: initialised to 0 and never set.
OBJECT_FIND = 0.0


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
        "object_find": OBJECT_FIND,
        "minutes": minutes,
        "success": success,
        "distance_m": d,
    }


def eval_py_task_sum(score: dict) -> float:
    """PRS's per-task sum (``eval.py``'s ``result``): grasp + object_find + deliver + human found."""
    deliver = score.get("deliver", score["grasp"] * score["human_found"])
    return score["grasp"] + score.get("object_find", OBJECT_FIND) + deliver + score["human_found"]


def aggregate(scores: list[dict], annotated: int) -> dict:
    """PRS's aggregates: ``Task SR`` by the simulator rule (the headline), Object Manipulation SR, Human
    Search SR, Time Used, ``Task SR (eval.py)`` by the published scorer's rule, and ``eval.py``: the four
    numbers exactly as the published ``eval.py`` reports them (its Task SR is 0, see the module doc)."""
    within = [s for s in scores if s["minutes"] <= TIME_LIMIT_MIN]
    n = float(annotated)
    grasp = sum(s["grasp"] for s in within) / n
    human = sum(s["human_found"] for s in within) / n
    used = sum(s["minutes"] for s in within) / max(1, len(scores))
    eval_task = sum(int(eval_py_task_sum(s) / 4) for s in within) / n
    return {
        "Task SR": sum(s["success"] for s in within) / n,
        "Object Manipulation SR": grasp,
        "Human Search SR": human,
        "Time Used": used,
        "Task SR (eval.py)": eval_task,
        "eval.py": {
            "Task SR": eval_task,
            "Object Manipulation SR": grasp,
            "Human Search SR": human,
            "Time Used": used,
        },
        "tasks": len(scores),
        "annotated": annotated,
    }
