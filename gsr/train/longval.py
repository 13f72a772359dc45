"""Long validation tasks: two goals of the same validation scene joined, plans longer than any training task.

    python -m gsr.train.longval --data DATASET --out DIR [--count 24] [--seed 0] [--min-plan N]

A length-generalisation check that never reads the test split: the dataset's ``val`` tasks are grouped
by their start scene, pairs of goals over the same objects become one conjunction (from the first task's start), and a pair is kept when the
planner solves it in at least ``--min-plan`` steps (default: one more than the longest ``train`` task's
plan, so every kept task is longer than anything trained on). The kept tasks are written as TaskSpec
files (category ``long-val``), each atomically, for ``bench_training.py --tasks`` or
``python -m gsr.train.diagnose``.

The same joining on the ``train`` split (``long_tasks(..., split="train")``, category ``long-train``) makes
the recipe's optional longer training tasks (``Recipe.joined_tasks``); no other split is ever joined.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
from pathlib import Path

from gsr.datagen.tasks import generated_tasks
from gsr.errors import GSRError
from gsr.io import write_bytes_atomic
from gsr.pddl.model import And, Formula
from gsr.pddl.parser import parse_formula
from gsr.pddl.writer import write_formula
from gsr.plan import api as plan_api
from gsr.resources import load_builtin_domain
from gsr.task_spec import TaskSpec, task_json


def _parts(goal: Formula) -> tuple[Formula, ...]:
    return goal.parts if isinstance(goal, And) else (goal,)


def joined_goal(first: str, second: str) -> Formula:
    """The conjunction of two goals' conjuncts, each once, in order."""
    parts: list[Formula] = []
    for text in (first, second):
        for p in _parts(parse_formula(text)):
            if p not in parts:
                parts.append(p)
    return And(tuple(parts))


def long_tasks(
    data: Path,
    count: int,
    seed: int,
    min_plan: int | None = None,
    split: str = "val",
    timeout: float = 10.0,
) -> list[TaskSpec]:
    """Up to ``count`` joined tasks of ``split`` (validation by default; ``train`` for the recipe's
    longer training tasks, never another split) whose plans have at least ``min_plan`` steps; a pair
    the planner does not solve within ``timeout`` seconds (most such pairs have conflicting goals) is
    skipped."""
    if split not in ("val", "train"):
        raise GSRError(f"joined tasks come from the val or train split, not {split!r}")
    domain = load_builtin_domain()
    if min_plan is None:
        min_plan = 1 + max((t.metadata.get("horizon", 0) for t in generated_tasks(data, "train")), default=0)
    scenes: dict[str, list[TaskSpec]] = {}
    for t in generated_tasks(data, split):
        # one scene: the same objects (the tasks of a scene start from different arrangements of them)
        scenes.setdefault(" ".join(sorted(n.id for n in t.initial.nodes)), []).append(t)
    pairs = [(a, b) for group in scenes.values() for i, a in enumerate(group) for b in group[i + 1 :]]
    random.Random(seed).shuffle(pairs)
    out: list[TaskSpec] = []
    for a, b in pairs:
        if len(out) >= count:
            break
        goal = joined_goal(a.goal, b.goal)
        if len(_parts(goal)) <= max(len(_parts(parse_formula(x.goal))) for x in (a, b)):
            continue  # one goal contains the other
        found = plan_api.plan_graph(domain, a.initial, goal, timeout=timeout)
        if not found.solved or found.plan is None or len(found.plan.steps) < min_plan:
            continue
        out.append(
            TaskSpec(
                id=f"long-{a.id}+{b.id.rsplit('-', 1)[-1]}",
                suite="gsr-datagen",
                category=f"long-{split}",
                instructions=(f"{a.instructions[0]} {b.instructions[0]}",),
                initial=a.initial,
                goal=write_formula(goal),
                metadata={"plan": len(found.plan.steps), "from": [a.id, b.id]},
            )
        )
    return out


def main(argv: list[str] | None = None) -> int:
    """Write the long validation tasks; print how many and their plan lengths."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, required=True, help="The gsr datagen folder (val and train splits).")
    ap.add_argument("--out", type=Path, required=True, help="Folder for the TaskSpec files.")
    ap.add_argument("--count", type=int, default=24, help="Tasks wanted (default 24).")
    ap.add_argument("--seed", type=int, default=0, help="Shuffle seed of the goal pairs.")
    ap.add_argument("--min-plan", type=int, help="Shortest plan kept (default: longest train task + 1).")
    args = ap.parse_args(argv)
    if args.count < 1:
        ap.error("--count must be >= 1")
    try:
        tasks = long_tasks(args.data, args.count, args.seed, args.min_plan)
        for t in tasks:
            write_bytes_atomic(args.out / f"{t.id}.json", task_json(t).encode())
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    plans = sorted(t.metadata["plan"] for t in tasks)
    print(json.dumps({"tasks": len(tasks), "plans": plans, "out": str(args.out)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
