"""Export generated tasks as TaskSpec files, so the suites runner can evaluate models on held-out tasks.

A task's first ``next_action`` row (empty history) holds everything a TaskSpec needs: the start
graph, the instruction and the PDDL goal; the row's ``heldout`` tag becomes the task's category.
"""

from __future__ import annotations

import glob
import json
from pathlib import Path

from gsr.datagen.schema import decode
from gsr.errors import GSRError
from gsr.io import write_bytes_atomic
from gsr.task_spec import TaskSpec, task_json


def generated_tasks(
    data: Path, split: str = "test", heldout: str | None = None, limit: int | None = None
) -> list[TaskSpec]:
    """TaskSpecs of the dataset's tasks in ``split`` (optionally one held-out kind), in file order."""
    files = sorted(glob.glob(str(data / "data" / split / "*.jsonl")))
    if not files:
        raise GSRError(f"{data}: no data/{split}/*.jsonl files")
    out: list[TaskSpec] = []
    for path in files:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                row = json.loads(line)
                if row["type"] != "next_action" or (heldout and row["heldout"] != heldout):
                    continue
                envelope, inp, _ = decode(row)
                if inp.history:
                    continue
                out.append(
                    TaskSpec(
                        id=f"gen-{envelope.task}",
                        suite="gsr-datagen",
                        category=envelope.heldout or split,
                        instructions=(inp.instruction,),
                        initial=inp.graph,
                        goal=inp.goal,
                        metadata={"horizon": envelope.horizon, "row": envelope.id},
                    )
                )
                if limit is not None and len(out) >= limit:
                    return out
    return out


def export_tasks(
    data: Path, out: Path, split: str = "test", heldout: str | None = None, limit: int | None = None
) -> int:
    """Write one TaskSpec JSON per task into ``out`` (atomically); the number written."""
    tasks = generated_tasks(data, split, heldout, limit)
    out.mkdir(parents=True, exist_ok=True)
    for task in tasks:
        write_bytes_atomic(out / f"{task.id}.json", task_json(task).encode())
    return len(tasks)
