"""Offline metrics of saved compact-format models on a dataset's validation split.

    python -m gsr.train.evaluate --data DATASET [--rows 400] [--tasks 80] [--seed 0] MODEL [MODEL ...]

For each model folder (written by the training recipe), one line: free next-step accuracy and ranking
accuracy (:func:`gsr.train.compact.ranking_accuracy`) on the first ``--rows`` rows of the seed-shuffled
``val`` split, and closed-loop constrained decoding on the first ``--tasks`` seed-shuffled ``val`` tasks
(:func:`gsr.train.compact.constrained_episodes`, with the goal window of the model's marker), with
the CPU seconds. The dataset's test split is never read. A folder that is not a compact-format model is a one-line error (exit 1).
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
from gsr.resources import load_builtin_domain
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


def evaluate(folder: Path, data: Path, rows: int, tasks: int, seed: int) -> dict[str, Any]:
    """The offline metrics of one model folder on ``data``'s validation split."""
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
    window = goal_window(folder)
    solved, n = (
        constrained_episodes(model, tokenizer, episodes, domain, version=version, goal_window=window)
        if tasks
        else (0, 0)
    )
    return {
        "model": str(folder),
        "val_rows": len(val),
        "free_accuracy": round(free, 3),
        "ranking_accuracy": round(rank, 3),
        "val_tasks_constrained": f"{solved}/{n}",
        "goal_window": window,
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
    args = ap.parse_args(argv)
    if args.rows < 1 or args.tasks < 0:
        ap.error("--rows must be >= 1 and --tasks >= 0")
    try:
        for folder in args.models:
            print(json.dumps(evaluate(folder, args.data, args.rows, args.tasks, args.seed)), flush=True)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
