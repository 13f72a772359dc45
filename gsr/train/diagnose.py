"""Where a saved compact-format model goes wrong on long tasks: lengths and first wrong steps.

    python -m gsr.train.diagnose --data DATASET --tasks DIR MODEL [--max-steps 24]

Prints JSON lines: (1) ``train`` / ``tasks`` length profiles: context tokens of the training rows (the
dataset's ``train`` split, inference naming) and of the tasks' queries along their planner trajectories,
scene objects, goal atoms and plan lengths; (2) one line per task of ``DIR`` (TaskSpec JSON files) with
a closed-loop constrained episode (as :func:`gsr.train.compact.constrained_episodes` runs it) and the
first *wrong* step: the first step after which the planner's remaining plan is not shorter than before
(a detour), with the step, the planner's step and the episode index. A diagnosis tool: selection never
reads tasks through it.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from statistics import mean
from typing import Any

from gsr.check import check_step
from gsr.errors import GSRError
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import And, Atom, Domain, Formula
from gsr.pddl.parser import parse_formula
from gsr.pddl.walk import subformulas
from gsr.plan import api as plan_api
from gsr.reason.compact import Naming, context_tokens, ground_goal, scene_objects
from gsr.reason.compact_decode import GOAL_ORDERS, CompactAnswerer
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.semantics import goal_holds, holds
from gsr.step import Step
from gsr.task_spec import load_task
from gsr.train.compact import constrained_episode, dataset_samples
from gsr.train.evaluate import load_compact


def goal_atoms(goal: Formula) -> int:
    """Atoms in a goal formula."""
    return sum(isinstance(f, Atom) for f in subformulas(goal))


def open_literals(goal: Formula, graph: SceneGraph, domain: Domain) -> int:
    """Goal literals that do not hold in ``graph`` (the ``F`` literals of the compact query)."""
    state = state_from_graph(graph, domain)
    grounded = ground_goal(goal, state, domain)
    parts = grounded.parts if isinstance(grounded, And) else (grounded,)
    return sum(not holds(domain, p, state) for p in parts)


def context_length(graph: SceneGraph, goal: Formula, history: tuple, domain: Domain, version: int) -> int:
    """Compact query tokens (inference naming) of a state, goal and history."""
    state = state_from_graph(graph, domain)
    naming = Naming.make(scene_objects(state, domain))
    return len(context_tokens(state, domain, goal, history, naming, version))


def plan_steps(domain: Domain, graph: SceneGraph, goal: Formula) -> list[Step] | None:
    """The planner's plan from ``graph`` (empty when the goal holds; None when unsolved)."""
    if goal_holds(domain, goal, state_from_graph(graph, domain)):
        return []
    found = plan_api.plan_graph(domain, graph, goal, timeout=10.0)
    if not found.solved or found.plan is None:
        return None
    return [Step(s.action, tuple(s.args)) for s in found.plan.steps]


def profile(values: list[int]) -> dict[str, Any]:
    """min / mean / p95 / max of integers."""
    if not values:
        return {}
    ordered = sorted(values)
    return {
        "n": len(ordered),
        "min": ordered[0],
        "mean": round(mean(ordered), 1),
        "p95": ordered[int(0.95 * (len(ordered) - 1))],
        "max": ordered[-1],
    }


def train_profile(data: Path, domain: Domain, version: int, limit: int | None) -> dict[str, Any]:
    """Length profile of the training rows."""
    rows = dataset_samples(data, "train", limit)
    lengths = [context_length(s.graph, s.goal, s.history, domain, version) for s in rows]
    objects = [len(scene_objects(state_from_graph(s.graph, domain), domain)) for s in rows]
    starts = [s for s in rows if not s.history]
    opened = [open_literals(s.goal, s.graph, domain) for s in rows]
    return {
        "profile": "train",
        "rows": len(rows),
        "context_tokens": profile(lengths),
        "objects": profile(objects),
        "goal_atoms": profile([goal_atoms(s.goal) for s in starts]),
        "history_steps": profile([len(s.history) for s in rows]),
        "open_goal_literals": profile(opened),
    }


def episode(
    answerer: CompactAnswerer, domain: Domain, graph: SceneGraph, goal: Formula, max_steps: int
) -> dict[str, Any]:
    """A constrained episode (:func:`gsr.train.compact.constrained_episode`) with the query length of
    every decision and the first step after which the planner's remaining plan is not shorter."""
    run = constrained_episode(answerer, domain, graph, goal, max_steps)
    decisions = len(run.steps) + (run.end == "no_pick")
    lengths = [
        context_length(run.graphs[i], goal, tuple(run.steps[:i]), domain, answerer.version)
        for i in range(decisions)
    ]
    first_wrong: dict[str, Any] | None = None
    left = plan_steps(domain, run.graphs[0], goal)
    for i, step in enumerate(run.steps):
        after = plan_steps(domain, run.graphs[i + 1], goal)
        if left is not None and (after is None or len(after) >= len(left)):
            first_wrong = {
                "index": i,
                "step": [step.action, *step.args],
                "planner": [left[0].action, *left[0].args] if left else None,
                "plan_left_before": len(left),
            }
            break
        left = after
    return {
        "solved": run.end == "solved",
        "steps": len(run.steps),
        "first_wrong": first_wrong,
        "context_tokens": lengths,
    }


def task_lines(
    model_dir: Path,
    tasks_dir: Path,
    domain: Domain,
    max_steps: int,
    goal_window: int | None = None,
    goal_order: str = "goal",
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """One line per task file, and the tasks' length profile along the planner trajectories."""
    model, tokenizer, version = load_compact(model_dir)
    answerer = CompactAnswerer(
        model, tokenizer, version=version, goal_window=goal_window, goal_order=goal_order
    )
    files = sorted(tasks_dir.glob("*.json"))
    if not files:
        raise GSRError(f"{tasks_dir}: no task files")
    out, lengths, objects, atoms, plans, opened = [], [], [], [], [], []
    for path in files:
        task = load_task(path)
        graph, goal = task.initial, parse_formula(task.goal)
        plan = plan_steps(domain, graph, goal) or []
        g, hist = graph, []
        for step in plan:
            lengths.append(context_length(g, goal, tuple(hist), domain, version))
            g = graph_with_state(g, check_step(domain, state_from_graph(g, domain), step).next_state)
            hist.append(step)
        objects.append(len(scene_objects(state_from_graph(graph, domain), domain)))
        atoms.append(goal_atoms(goal))
        plans.append(len(plan))
        opened.append(open_literals(goal, graph, domain))
        line = {"task": task.id, "category": task.category, "plan": len(plan)}
        line["objects"], line["goal_atoms"] = objects[-1], atoms[-1]
        line.update(episode(answerer, domain, graph, goal, max_steps))
        line["context_tokens"] = profile(line["context_tokens"])
        out.append(line)
    summary = {
        "profile": "tasks",
        "tasks": len(files),
        "context_tokens_along_plans": profile(lengths),
        "objects": profile(objects),
        "goal_atoms": profile(atoms),
        "plan_steps": profile(plans),
        "open_goal_literals_at_start": profile(opened),
        "solved": sum(x["solved"] for x in out),
        "goal_window": goal_window,
        "goal_order": goal_order,
    }
    return out, summary


def main(argv: list[str] | None = None) -> int:
    """Print the profiles and one line per task."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("model", type=Path, help="A compact-format model folder.")
    ap.add_argument("--data", type=Path, required=True, help="The gsr datagen folder (its train split).")
    ap.add_argument("--tasks", type=Path, required=True, help="A folder of TaskSpec JSON files.")
    ap.add_argument("--rows", type=int, default=0, help="Training rows profiled (0: all).")
    ap.add_argument("--max-steps", type=int, default=24, help="Episode step limit (default 24).")
    ap.add_argument(
        "--goal-window", type=int, help="Show the model at most N open goal literals (default: off)."
    )
    ap.add_argument(
        "--goal-order",
        choices=GOAL_ORDERS,
        default="goal",
        help="Order in which open goal literals enter the window (default: the goal's).",
    )
    ap.add_argument("--no-train-profile", action="store_true", help="Skip the training rows' profile.")
    args = ap.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    domain = load_builtin_domain()
    try:
        _, _, version = load_compact(args.model)
        if not args.no_train_profile:
            print(json.dumps(train_profile(args.data, domain, version, args.rows or None)), flush=True)
        lines, summary = task_lines(
            args.model, args.tasks, domain, args.max_steps, args.goal_window, args.goal_order
        )
        print(json.dumps(summary), flush=True)
        for line in lines:
            print(json.dumps(line), flush=True)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
