"""Offline metrics of saved compact-format models on a dataset's validation split.

    python -m gsr.train.evaluate --data DATASET [--rows 400] [--tasks 80] [--seed 0] MODEL [MODEL ...]

For each model folder (written by the training recipe), one line: free next-step accuracy and ranking
accuracy (:func:`gsr.train.compact.ranking_accuracy`) on the first ``--rows`` rows of the seed-shuffled
``val`` split, and closed-loop constrained decoding on the first ``--tasks`` seed-shuffled ``val`` tasks
(:func:`gsr.train.compact.constrained_episodes`, with the goal window and order of the model's marker,
or ``--goal-window`` / ``--goal-order``), with the CPU seconds; ``--long-tasks DIR`` also runs the
TaskSpec files of DIR closed loop (e.g. ``python -m gsr.train.longval``'s long validation tasks). The
dataset's test split is never read. A folder that is not a compact-format model is a one-line error (exit 1).
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
from pathlib import Path
from typing import Any

from gsr.datagen.tasks import generated_tasks
from gsr.errors import GSRError
from gsr.pddl.parser import parse_formula
from gsr.reason.compact import FORMATS, MARKER
from gsr.reason.compact_decode import GOAL_ORDERS
from gsr.resources import load_builtin_domain
from gsr.task_spec import load_task
from gsr.train.compact import accuracy, constrained_episodes, dataset_samples, ranking_accuracy


def load_compact(folder: Path) -> tuple[Any, Any, int]:
    """(model, tokenizer, format version) of a compact-format model folder."""
    try:
        info = json.loads((folder / MARKER).read_text(encoding="utf-8"))
        version = FORMATS[info["format"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise GSRError(f"{folder}: not a compact-format model ({MARKER}: {exc})") from None
    from transformers import AutoModelForCausalLM, PreTrainedTokenizerFast

    try:
        model = AutoModelForCausalLM.from_pretrained(folder, local_files_only=True)
        tokenizer = PreTrainedTokenizerFast.from_pretrained(folder, local_files_only=True)
    except (OSError, ValueError) as exc:
        raise GSRError(f"{folder}: cannot load the model: {exc}") from None
    model.eval()
    return model, tokenizer, version


def goal_window(folder: Path) -> int | None:
    """The goal window a compact-format model folder's marker sets (None: none)."""
    try:
        window = json.loads((folder / MARKER).read_text(encoding="utf-8")).get("goal_window")
    except (OSError, ValueError, AttributeError) as exc:
        raise GSRError(f"{folder}: not a compact-format model ({MARKER}: {exc})") from None
    return window if isinstance(window, int) and not isinstance(window, bool) and window > 0 else None


def goal_order(folder: Path) -> str:
    """The order in which a model folder's marker lets open goal literals enter its window."""
    try:
        order = json.loads((folder / MARKER).read_text(encoding="utf-8")).get("goal_order", "goal")
    except (OSError, ValueError, AttributeError) as exc:
        raise GSRError(f"{folder}: not a compact-format model ({MARKER}: {exc})") from None
    if order not in GOAL_ORDERS:
        raise GSRError(f"{folder}: goal_order {order!r} is not one of {', '.join(GOAL_ORDERS)}")
    return order


def evaluate(
    folder: Path,
    data: Path,
    rows: int,
    tasks: int,
    seed: int,
    long_tasks: Path | None = None,
    window: int | None = None,
    order: str | None = None,
) -> dict[str, Any]:
    """The offline metrics of one model folder on ``data``'s validation split (and on the TaskSpec
    files of ``long_tasks``); ``window`` / ``order`` replace the marker's goal window and order."""
    import torch

    torch.set_num_threads(1)
    domain = load_builtin_domain()
    val = dataset_samples(data, "val")
    random.Random(seed).shuffle(val)
    val = val[:rows]
    episodes = [(t.initial, parse_formula(t.goal)) for t in generated_tasks(data, "val")]
    random.Random(seed).shuffle(episodes)
    episodes = episodes[:tasks]
    model, tokenizer, version = load_compact(folder)
    c0 = time.process_time()
    free = accuracy(model, val, domain, tokenizer, version)
    rank = ranking_accuracy(model, val, domain, tokenizer, version)
    window = goal_window(folder) if window is None else window
    order = goal_order(folder) if order is None else order
    solved, n = (
        constrained_episodes(
            model, tokenizer, episodes, domain, version=version, goal_window=window, goal_order=order
        )
        if tasks
        else (0, 0)
    )
    more: dict[str, Any] = {}
    if long_tasks is not None:
        files = sorted(long_tasks.glob("*.json"))
        if not files:
            raise GSRError(f"{long_tasks}: no task files")
        specs = [load_task(f) for f in files]
        pairs = [(t.initial, parse_formula(t.goal)) for t in specs]
        ok, m = constrained_episodes(
            model, tokenizer, pairs, domain, version=version, goal_window=window, goal_order=order
        )
        more["long_tasks_constrained"] = f"{ok}/{m}"
    return {
        "model": str(folder),
        "val_rows": len(val),
        "free_accuracy": round(free, 3),
        "ranking_accuracy": round(rank, 3),
        "val_tasks_constrained": f"{solved}/{n}",
        **more,
        "goal_window": window,
        "goal_order": order,
        "cpu_seconds": round(time.process_time() - c0, 1),
    }


def main(argv: list[str] | None = None) -> int:
    """Print one JSON line per model."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("models", nargs="+", type=Path, help="Compact-format model folders.")
    ap.add_argument(
        "--data", type=Path, required=True, help="The gsr datagen folder (its val split is read)."
    )
    ap.add_argument("--rows", type=int, default=400, help="Validation rows (default 400).")
    ap.add_argument("--tasks", type=int, default=80, help="Validation tasks run closed loop (default 80).")
    ap.add_argument("--seed", type=int, default=0, help="Shuffle seed of the val rows and tasks.")
    ap.add_argument("--long-tasks", type=Path, help="Also run these TaskSpec files closed loop.")
    ap.add_argument("--goal-window", type=int, help="Goal window instead of the marker's.")
    ap.add_argument("--goal-order", choices=GOAL_ORDERS, help="Goal order instead of the marker's.")
    args = ap.parse_args(argv)
    if args.rows < 1 or args.tasks < 0:
        ap.error("--rows must be >= 1 and --tasks >= 0")
    if args.goal_window is not None and args.goal_window < 1:
        ap.error("--goal-window must be >= 1")
    try:
        for folder in args.models:
            line = evaluate(
                folder,
                args.data,
                args.rows,
                args.tasks,
                args.seed,
                args.long_tasks,
                args.goal_window,
                args.goal_order,
            )
            print(json.dumps(line), flush=True)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
