"""Cross-check our PRS metrics against PRS's own ``eval.py`` (loaded at run time from the user's folder).

PRS's ``evaluate(annotations, submission, phase)`` scores entries that carry the evaluator's fields
(``tar_object_name``, ``target_object_type``, ``npc_position``), as its simulator's result records do; our
submission holds only the agent's side, so the check adds those fields from the task file, as PRS's
server does, then runs ``evaluate`` and ``delivery_task_score`` and compares with ``prs_metrics``: every
number ``eval.py`` reports (its Task SR, 0 for any submission as published, included) and the Task SR by
the in-simulator scorer's rule.

Usage: ``python -m gsr.benchmarks.delivery.prs_eval_check EVAL_PY TASKS SUBMISSION``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import sys
import tempfile
from pathlib import Path

from gsr.benchmarks.delivery.prs_metrics import aggregate, score_entry
from gsr.benchmarks.delivery.prs_tasks import PrsTruth


def _truth(t: dict) -> PrsTruth:
    p, o = t["npc_position"], t["target_object_pos"]
    return PrsTruth(
        t["npc_id"], t["npc_name"], (p["x"], p["y"], p["z"]), t.get("npc_action", ""),
        t["target_object_name"], t["target_object_type"], (o["x"], o["y"], o["z"]),
    )  # fmt: skip


#: What ``eval.py`` reports.
EVAL_KEYS = ("Task SR", "Object Manipulation SR", "Human Search SR", "Time Used")


def compare(eval_py: Path, tasks_file: Path, submission: dict) -> dict:
    """PRS's numbers and ours on a submission, side by side: ``eval.py``'s four aggregates (its Task SR
    included, 0 as published) against ``aggregate``'s ``eval.py`` block, and the simulator rule's Task SR
    (``delivery_task_score``'s parts: exact object, within 3 m, within 10 minutes) against our ``Task SR``;
    ``equal`` when every pair is identical."""
    spec = importlib.util.spec_from_file_location("prs_eval", eval_py)
    if spec is None or spec.loader is None:
        raise ValueError(f"{eval_py}: cannot load")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    tasks = json.loads(Path(tasks_file).read_text(encoding="utf-8"))
    merged = {}
    for tid, entry in submission.items():
        t = tasks[tid]
        merged[tid] = dict(
            entry,
            tar_object_name=t["target_object_name"],
            target_object_type=t["target_object_type"],
            npc_position=t["npc_position"],
        )
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "submission.json"
        path.write_text(json.dumps(merged), encoding="utf-8")
        with contextlib.redirect_stdout(io.StringIO()):
            prs = module.evaluate(str(tasks_file), str(path), "dev")["submission_result"]
    # PRS's per-task scores; success as its in-simulator scorer counts it (object_find = 1 with the exact
    # object, so all four parts sum to 4), within 10 minutes as eval.py requires
    per_task = [module.delivery_task_score(e) for e in merged.values()]
    prs_success = sum(
        s["sub_result"]["grasp"] == 1 and s["sub_result"]["human_find"] == 1 and s["time"] <= 10
        for s in per_task
    ) / len(tasks)
    ours = aggregate([score_entry(e, _truth(tasks[tid])) for tid, e in submission.items()], len(tasks))
    # every number eval.py reports (its Task SR included) against ours, and the simulator rule's Task SR
    equal = all(abs(prs[k] - ours["eval.py"][k]) < 1e-12 for k in EVAL_KEYS) and (
        abs(prs_success - ours["Task SR"]) < 1e-12
    )
    return {
        "eval.py": {k: prs[k] for k in EVAL_KEYS},
        "ours (eval.py rule)": ours["eval.py"],
        "simulator rule Task SR": {"prs": prs_success, "ours": ours["Task SR"]},
        "equal": equal,
    }


def main(argv: list[str]) -> int:
    """CLI: print both sets of numbers; exit 0 when they agree, 2 when not, 1 on bad input."""
    if len(argv) != 3:
        print(
            "usage: python -m gsr.benchmarks.delivery.prs_eval_check EVAL_PY TASKS SUBMISSION",
            file=sys.stderr,
        )
        return 1
    try:
        submission = json.loads(Path(argv[2]).read_text(encoding="utf-8"))
        result = compare(Path(argv[0]), Path(argv[1]), submission)
    except (OSError, ValueError, KeyError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(json.dumps(result, indent=1))
    return 0 if result["equal"] else 2


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
