"""Checker ablation for a trained reasoner model: what the checker, the repair loop and constrained
decoding buy, measured with the suites runner (issue 6).

Every condition is one ``gsr bench run tasks`` call on the same task folders with the same model:

- ``open-loop``: ``gsr.train.openloop:OpenLoopAgent`` — the model's steps go straight to execution,
  the first inapplicable one ends the episode (no checker).
- ``checker``: ``--agent reasoner`` with ``max_repairs=0`` — a rejected step ends the episode, but it
  is never executed.
- ``checker+repair``: the reasoner with ``max_repairs=R`` — the diagnosis goes back to the model.
- ``checker+constrained``: the reasoner with the repairs and constrained decoding (the model chooses
  among the checker's applicable steps that lead to a state not visited yet in the episode).
- ``open-loop+constrained`` (not in the default set): the open loop with constrained decoding.

``--recipe cpu|gpu --out DIR`` runs the whole trained-reasoner recipe (data, from-scratch training,
held-out tasks, the four default conditions; :mod:`gsr.benchmarks.training_recipe`); its last line is
``trained model: checker+constrained S/N, checker+repair R/N, checker T/N, open loop O/N (held-out
generated tasks)``.

    python benchmarks/bench_training.py --model MODEL_DIR --tasks gen=GEN_TASKS --tasks gsr-bench=GB_TASKS \\
        --workers 8 --max-steps 24 --out ablation.json --markdown

Task folders come from ``gsr datagen-tasks`` (held-out generated tasks) and ``gsr bench export gsr-bench``.
The JSON (written atomically) holds every condition's runner metrics; ``--markdown`` prints the table
that docs/training.md records.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any

from gsr.benchmarks.checker_ablation import CONDITIONS, DEFAULT_CONDITIONS, markdown, run_condition
from gsr.benchmarks.training_recipe import run_recipe

from gsr.io import write_text_atomic


def main(argv: list[str] | None = None) -> int:
    """Parse options, run every condition on every task set, write JSON, print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", help="A checkpoint folder written by gsr train.")
    ap.add_argument("--tasks", action="append", help="NAME=FOLDER of TaskSpec files (repeatable).")
    ap.add_argument(
        "--recipe",
        choices=("cpu", "gpu"),
        help="Generate data, train a compact step model from scratch, evaluate it (needs --out DIR).",
    )
    ap.add_argument("--seed", type=int, default=0, help="Recipe seed (data and held-out tasks; model too).")
    ap.add_argument(
        "--train-seed",
        type=int,
        help="Recipe: seed of the model's initialisation and training order (default --seed): another "
        "training on the same data and held-out tasks.",
    )
    ap.add_argument(
        "--train-budget",
        type=float,
        help="Recipe: train for this many CPU seconds in all instead of the recipe's step counts "
        "(cpu: 1500 + 750 steps; gpu: by CPU time, 1500 s); the steps then depend on the machine.",
    )
    ap.add_argument(
        "--gsr-bench", type=int, default=6, help="Recipe: GSR-Bench dev tasks per category (0: none)."
    )
    ap.add_argument("--conditions", default=",".join(DEFAULT_CONDITIONS), help="Comma-separated subset.")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-steps", type=int, default=24)
    ap.add_argument("--repairs", type=int, default=2, help="max_repairs of the repair conditions.")
    ap.add_argument("--out", type=Path, help="Write all figures as JSON here (atomically).")
    ap.add_argument("--markdown", action="store_true")
    args = ap.parse_args(argv)
    if args.recipe:
        if args.out is None:
            ap.error("--recipe needs --out DIR (the folder for data, model, tasks and figures)")
        if args.out.exists() and not args.out.is_dir():
            ap.error(f"--out {args.out}: not a folder")
        return run_recipe(
            args.recipe,
            args.out,
            args.seed,
            args.workers,
            args.max_steps,
            args.repairs,
            args.gsr_bench,
            args.train_budget,
            args.train_seed,
        )
    if not args.model or not args.tasks:
        ap.error("give --model and --tasks, or --recipe cpu|gpu --out DIR")
    if not (Path(args.model) / "config.json").is_file():
        ap.error(f"--model {args.model}: no config.json (not a checkpoint folder)")
    sets: dict[str, str] = {}
    for spec in args.tasks:
        name, sep, folder = spec.partition("=")
        if not sep or not Path(folder).is_dir():
            ap.error(f"--tasks {spec}: expected NAME=FOLDER with an existing folder")
        sets[name] = folder
    names = [c.strip() for c in args.conditions.split(",") if c.strip()]
    unknown = [c for c in names if c not in CONDITIONS]
    if unknown:
        ap.error(f"--conditions: unknown {unknown}; choose from {', '.join(CONDITIONS)}")
    table: dict[str, list[dict[str, Any]]] = {s: [] for s in sets}
    for name in names:
        for s, folder in sets.items():
            row = run_condition(name, args.model, folder, args.workers, args.max_steps, args.repairs)
            table[s].append(row)
            print(json.dumps({"set": s, **row}), file=sys.stderr, flush=True)
    if args.out:
        info = {"model": str(args.model), "max_steps": args.max_steps, "repairs": args.repairs}
        write_text_atomic(args.out, json.dumps({**info, "sets": table}, indent=1))
    if args.markdown:
        print(markdown(table))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    raise SystemExit(main())
