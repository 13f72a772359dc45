"""The trained-reasoner recipes behind ``bench_training.py --recipe cpu|gpu --out DIR`` (issue 21).

One command generates the data, trains a compact-format step model from scratch, exports held-out
generated tasks (unseen object-target pairs, colours, longer horizons) and GSR-Bench dev tasks, and
runs the four conditions (open loop, checker, checker + repair, checker + constrained decoding) with
the suites runner; the planner never takes over. Everything lands under DIR:

    DIR/dataset/           gsr datagen output          DIR/model/      the trained folder
    DIR/tasks-generated/   held-out TaskSpec files     DIR/tasks-gsr-bench/   GSR-Bench dev tasks
    DIR/recipe.json        every figure (written atomically)
"""

from __future__ import annotations

import json
import os
import random
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from gsr.benchmarks.checker_ablation import DEFAULT_CONDITIONS, markdown, run_condition
from gsr.benchmarks.cli import load_suite_tasks

from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.datagen.tasks import generated_tasks
from gsr.errors import GSRError
from gsr.io import write_bytes_atomic, write_text_atomic
from gsr.pddl.parser import parse_formula
from gsr.reason.compact import build_tokenizer
from gsr.resources import load_builtin_domain
from gsr.task_spec import task_json
from gsr.train.compact import (
    CompactSpec,
    accuracy,
    constrained_episodes,
    cosine,
    dataset_samples,
    fit,
    new_model,
    planner_samples,
    ranking_accuracy,
    recovery_samples,
    rollout_samples,
    save,
    spec_dict,
    windowed_samples,
)
from gsr.train.longval import long_tasks


@dataclass(frozen=True)
class Recipe:
    """Data sizes and time budgets of one recipe."""

    samples: int  # gsr datagen rows
    recovery: int  # off-plan recovery rows
    train_seconds: float  # first round: CPU seconds of the training process (a cap when steps are set)
    dagger_tasks: int  # training tasks the model is rolled out on
    dagger_seconds: float  # training after the on-policy rows are added (a cap when steps are set)
    threads: int
    # steps of each round: the training, and the learning-rate schedule, are the same on every machine;
    # None: as many steps as the CPU seconds allow (the learning rate then follows CPU time)
    train_steps: int | None = None
    dagger_steps: int | None = None
    hidden: int = 128
    layers: int = 3
    heads: int = 4
    intermediate: int = 256
    batch_size: int = 32
    lr: float = 2e-3
    format_version: int = 3  # gsr.reason.compact format (FORMATS)
    group: int = 1  # batches drawn at once and sorted by length (fit's group: less padding)
    select_every: int = 0  # round 2: score the model every so many steps, keep the best (0: the last)
    select_rows: int = 200  # validation rows of the selection score (ranking accuracy)
    dagger_constrained: bool = False  # DAgger also rolls out with constrained decoding
    # the saved model's answerer shows at most this many goal literals that do not hold yet (goal
    # serialisation for goals longer than the training tasks'; None: the whole goal)
    goal_window: int | None = None
    # training rows, selection rows and DAgger rollouts seen through goal_window as decoding sees them
    # (gsr.train.compact.windowed_samples: the windowed goal, labelled for it by the planner)
    train_window: bool = False
    goal_order: str = "goal"  # the order open goal literals enter the window (compact_decode.GOAL_ORDERS)
    # longer training tasks: this many joined train tasks (two train goals of one scene, plans longer than
    # any train task's: gsr.train.longval.long_tasks on the train split) add the planner's episodes as rows,
    # seen through goal_window in goal_order as decoding sees them (compact.planner_samples); 0: none
    joined_tasks: int = 0
    joined_timeout: float = 1.0  # planner seconds per candidate pair (conflicting goals are unsolvable)


RECIPES = {
    # 2000 + 1000 steps on one thread in length-sorted batches (~0.3 CPU-s a step on the 2-core
    # development machine); the CPU seconds are a cap that a slower machine reaches first
    "cpu": Recipe(
        samples=30000,
        recovery=1500,
        train_seconds=1500,
        dagger_tasks=100,
        dagger_seconds=750,
        threads=1,
        train_steps=2000,
        dagger_steps=1000,
        group=8,
        select_every=250,
        dagger_constrained=True,
        goal_window=1,
        goal_order="dependencies",
    ),
    "gpu": Recipe(
        samples=200000,
        recovery=20000,
        train_seconds=900,
        dagger_tasks=2000,
        dagger_seconds=600,
        threads=8,
        hidden=256,
        layers=6,
        heads=8,
        intermediate=768,
        batch_size=128,
        lr=1e-3,
    ),
}
HELDOUT_KINDS = ("pair", "color", "horizon")
HELDOUT_TASKS = 24


def log(msg: str) -> None:
    """Progress on stderr."""
    print(msg, file=sys.stderr, flush=True)


def start_tasks(data: Path, split: str, count: int, seed: int) -> list[tuple[Any, Any]]:
    """(start graph, goal) of ``count`` random tasks of ``split`` (for the on-policy rounds)."""
    starts = [s for s in dataset_samples(data, split) if not s.history]
    random.Random(seed).shuffle(starts)
    return [(s.graph, s.goal) for s in starts[:count]]


def export_heldout(data: Path, out: Path, count: int) -> dict[str, int]:
    """Write ``count`` held-out test tasks: up to count/3 of each kind (pair, colour, horizon), the rest
    filled from the kinds that have more (pair scenes yield few tasks); returns the count per kind."""
    by_kind = {k: generated_tasks(data, "test", k) for k in HELDOUT_KINDS}
    chosen = {k: v[: count // len(HELDOUT_KINDS)] for k, v in by_kind.items()}
    rest = [t for k in HELDOUT_KINDS for t in by_kind[k][len(chosen[k]) :]]
    missing = count - sum(map(len, chosen.values()))
    for t in rest[: max(0, missing)]:
        chosen[t.category].append(t)
    for tasks in chosen.values():
        for t in tasks:
            write_bytes_atomic(out / f"{t.id}.json", task_json(t).encode())
    return {k: len(v) for k, v in chosen.items()}


def gsr_bench_dev(out: Path, per_category: int) -> int:
    """Export the ``per_category`` lowest-numbered GSR-Bench dev tasks of each category; 0 without the data."""
    try:
        tasks = load_suite_tasks("gsr-bench", None, None, 0, None)
    except (GSRError, OSError) as exc:
        log(f"GSR-Bench dev: skipped ({exc})")
        return 0
    chosen: dict[str, list] = {}
    for t in sorted(tasks, key=lambda t: int("".join(filter(str.isdigit, t.id)) or 0)):
        if len(chosen.setdefault(t.category, [])) < per_category:
            chosen[t.category].append(t)
    n = 0
    for group in chosen.values():
        for t in group:
            write_text_atomic(out / f"{t.id}.json", task_json(t) + "\n")
            n += 1
    return n


VAL_ROWS = 100  # validation rows of the reported accuracies (the selection uses the next ones)
VAL_TASKS = 40  # validation tasks of the reported closed-loop constrained-decoding score


def train_model(
    cfg: Recipe, data: Path, model_dir: Path, seed: int, data_seed: int | None = None
) -> dict[str, Any]:
    """Trajectory + recovery rows, first training round, DAgger round, save; the training figures.

    ``seed`` drives the model's initialisation, the row order, the namings and the recovery rows;
    ``data_seed`` (default ``seed``) picks the validation rows and the DAgger tasks."""
    import torch

    torch.set_num_threads(cfg.threads)
    domain = load_builtin_domain()
    data_seed = seed if data_seed is None else data_seed
    figures: dict[str, Any] = {}
    t0, c0 = time.perf_counter(), time.process_time()
    samples = dataset_samples(data, "train")
    val_all = dataset_samples(data, "val")
    random.Random(data_seed).shuffle(val_all)
    val = val_all[:VAL_ROWS]
    select_rows = val_all[VAL_ROWS : VAL_ROWS + cfg.select_rows]
    val_tasks = [(t.initial, parse_formula(t.goal)) for t in generated_tasks(data, "val")]
    random.Random(data_seed).shuffle(val_tasks)
    val_tasks = val_tasks[:VAL_TASKS]
    recovery = recovery_samples(samples, cfg.recovery, seed, domain)
    rows = samples + recovery
    if cfg.joined_tasks:
        j0 = time.process_time()
        long = long_tasks(data, cfg.joined_tasks, data_seed, split="train", timeout=cfg.joined_timeout)
        starts = [(t.initial, parse_formula(t.goal)) for t in long]
        joined = planner_samples(starts, domain, cfg.goal_window, cfg.goal_order)
        rows = rows + joined
        figures["joined"] = {
            "tasks": len(long),
            "rows": len(joined),
            "cpu_seconds": round(time.process_time() - j0, 1),
        }
        log(f"joined train tasks: {figures['joined']}")
    window = cfg.goal_window if cfg.train_window else None
    if window is not None:
        w0 = time.process_time()
        whole = rows
        rows = windowed_samples(rows, domain, window, cfg.goal_order)
        select_rows = windowed_samples(select_rows, domain, window, cfg.goal_order)
        figures["windowed_rows"] = {
            "changed": len(rows) - len({id(r) for r in whole} & {id(r) for r in rows}),
            "dropped": len(whole) - len(rows),
            "cpu_seconds": round(time.process_time() - w0, 1),
        }
        log(f"rows seen through goal window {window}: {figures['windowed_rows']}")
    figures["rows"] = {
        "trajectory": len(samples),
        "recovery": len(recovery),
        "val": len(val),
        "select": len(select_rows),
        "val_tasks": len(val_tasks),
    }
    figures["prepare_seconds"] = round(time.perf_counter() - t0, 1)
    figures["prepare_cpu_seconds"] = round(time.process_time() - c0, 1)
    log(f"rows: {figures['rows']} in {figures['prepare_seconds']} s")
    tokenizer = build_tokenizer(domain)
    vocab = tokenizer.get_vocab()
    spec = CompactSpec(cfg.hidden, cfg.layers, cfg.heads, cfg.intermediate)
    model = new_model(tokenizer, spec, seed)
    device = "cuda" if torch.cuda.is_available() else "cpu"
    model.to(device)
    if cfg.train_steps and cfg.dagger_steps:
        first = cfg.train_steps / (cfg.train_steps + cfg.dagger_steps)
    else:
        first = cfg.train_seconds / (cfg.train_seconds + cfg.dagger_seconds)

    def sched1(p: float) -> float:
        return cosine()(p * first)

    def sched2(p: float) -> float:
        return cosine()(first + p * (1 - first))

    v = cfg.format_version
    r1, opt = fit(
        model,
        rows,
        domain,
        vocab,
        cfg.train_seconds,
        seed,
        cfg.batch_size,
        cfg.lr,
        None,
        sched1,
        log,
        cfg.train_steps,
        v,
        group=cfg.group,
    )
    figures["round1"] = r1.__dict__
    figures["round1_val_accuracy"] = round(accuracy(model, val, domain, tokenizer, v), 3)
    figures["round1_val_ranking"] = round(ranking_accuracy(model, val, domain, tokenizer, v), 3)
    log(
        f"round 1: {r1}, val next-step accuracy {figures['round1_val_accuracy']}, "
        f"ranking accuracy {figures['round1_val_ranking']}"
    )
    d0, dc0 = time.perf_counter(), time.process_time()
    tasks = start_tasks(data, "train", cfg.dagger_tasks, data_seed)
    order = cfg.goal_order
    dagger, solved = rollout_samples(
        model, tokenizer, tasks, domain, version=v, goal_window=window, goal_order=order
    )
    solved_c = 0
    if cfg.dagger_constrained:
        more, solved_c = rollout_samples(
            model,
            tokenizer,
            tasks,
            domain,
            max_steps=16,
            version=v,
            constrained=True,
            goal_window=window,
            goal_order=order,
        )
        dagger += more
    figures["dagger"] = {
        "tasks": cfg.dagger_tasks,
        "solved_free": solved,
        "solved_constrained": solved_c,
        "rows": len(dagger),
        "seconds": round(time.perf_counter() - d0, 1),
        "cpu_seconds": round(time.process_time() - dc0, 1),
    }
    log(f"dagger: {figures['dagger']}")
    # the on-policy rows are where the model goes wrong: weigh them like the rest of the data together
    rows = rows + dagger * max(1, len(rows) // max(1, 3 * len(dagger)))
    r2, _ = fit(
        model,
        rows,
        domain,
        vocab,
        cfg.dagger_seconds,
        seed + 1,
        cfg.batch_size,
        cfg.lr,
        opt,
        sched2,
        log,
        cfg.dagger_steps,
        v,
        group=cfg.group,
        select=(lambda m: ranking_accuracy(m, select_rows, domain, tokenizer, v))
        if cfg.select_every
        else None,
        select_every=cfg.select_every,
    )
    figures["round2"] = r2.__dict__
    figures["val_accuracy"] = round(accuracy(model, val, domain, tokenizer, v), 3)
    figures["val_ranking"] = round(ranking_accuracy(model, val, domain, tokenizer, v), 3)
    if window is not None:  # the same val rows through the window, labelled for the windowed goal
        val_w = windowed_samples(val, domain, window, cfg.goal_order)
        figures["val_ranking_window"] = round(ranking_accuracy(model, val_w, domain, tokenizer, v), 3)
    ok, n = constrained_episodes(
        model, tokenizer, val_tasks, domain, version=v, goal_window=cfg.goal_window, goal_order=cfg.goal_order
    )
    figures["val_tasks_constrained"] = f"{ok}/{n}"
    figures["goal_window"] = cfg.goal_window
    figures["goal_order"] = cfg.goal_order
    if cfg.goal_window is not None:
        ok, n = constrained_episodes(model, tokenizer, val_tasks, domain, version=v)
        figures["val_tasks_constrained_whole_goal"] = f"{ok}/{n}"
    figures["train_seconds"] = round(r1.seconds + r2.seconds, 1)
    figures["train_cpu_seconds"] = round(r1.cpu_seconds + r2.cpu_seconds, 1)
    figures["parameters"] = sum(p.numel() for p in model.parameters())
    figures["spec"] = spec_dict(spec)
    log(
        f"round 2: {r2}, val next-step accuracy {figures['val_accuracy']}, ranking accuracy "
        f"{figures['val_ranking']}, val tasks (constrained) {figures['val_tasks_constrained']}"
    )
    model.to("cpu")
    info = {"recipe": cfg.__dict__, "seed": seed, "data_seed": data_seed, **figures}
    save(model, tokenizer, model_dir, info, v, goal_window=cfg.goal_window, goal_order=cfg.goal_order)
    return figures


def run_recipe(
    name: str,
    out: Path,
    seed: int,
    workers: int,
    max_steps: int,
    repairs: int,
    gsr_bench: int,
    train_budget: float | None = None,
    train_seed: int | None = None,
) -> int:
    """Data, training, task export and the ablation; prints the table and the summary line.

    ``seed`` makes the data (and so the held-out tasks); ``train_seed`` (default ``seed``) the model's
    initialisation and training order, so several trainings can be measured on the same tasks.

    ``train_budget`` (CPU seconds) replaces the recipe's step counts by that much training time, split 2:1
    between the rounds (as many steps as the machine manages in it)."""
    cfg = RECIPES[name]
    if os.environ.get("GSR_RECIPE_SCALE"):  # tests: a tiny version of the same pipeline
        scale = float(os.environ["GSR_RECIPE_SCALE"])
        cfg = replace(
            cfg,
            samples=max(2000, int(cfg.samples * scale)),
            recovery=int(cfg.recovery * scale),
            train_seconds=cfg.train_seconds * scale,
            train_steps=max(1, int(cfg.train_steps * scale)) if cfg.train_steps else None,
            dagger_steps=max(1, int(cfg.dagger_steps * scale)) if cfg.dagger_steps else None,
            dagger_tasks=max(2, int(cfg.dagger_tasks * scale)),
            dagger_seconds=cfg.dagger_seconds * scale,
            select_every=max(1, int(cfg.select_every * scale)) if cfg.select_every else 0,
            select_rows=max(8, int(cfg.select_rows * scale)),
            hidden=32,
            layers=1,
            heads=2,
            intermediate=64,
        )
    if train_budget is not None:
        cfg = replace(
            cfg,
            train_seconds=train_budget * 2 / 3,
            dagger_seconds=train_budget / 3,
            train_steps=None,
            dagger_steps=None,
        )
    out.mkdir(parents=True, exist_ok=True)
    data, model_dir = out / "dataset", out / "model"
    train_seed = seed if train_seed is None else train_seed
    report: dict[str, Any] = {"recipe": name, "config": cfg.__dict__, "seed": seed, "train_seed": train_seed}
    t0 = time.perf_counter()
    if not (data / "manifest.json").is_file():
        generate_dataset(RunConfig(data, cfg.samples, seed=seed), progress=False)
    report["datagen_seconds"] = round(time.perf_counter() - t0, 1)
    if (model_dir / "config.json").is_file():
        log(f"{model_dir}: already trained, reusing it")
        report["training"] = json.loads((model_dir / "gsr_training.json").read_text())
    else:
        report["training"] = train_model(cfg, data, model_dir, train_seed, data_seed=seed)
    sets = {"generated": out / "tasks-generated"}
    report["generated_tasks"] = export_heldout(data, sets["generated"], HELDOUT_TASKS)
    if gsr_bench and gsr_bench_dev(out / "tasks-gsr-bench", gsr_bench):
        sets["gsr-bench"] = out / "tasks-gsr-bench"
    table: dict[str, list[dict[str, Any]]] = {s: [] for s in sets}
    for cond in DEFAULT_CONDITIONS:
        for s, folder in sets.items():
            row = run_condition(cond, str(model_dir), str(folder), workers, max_steps, repairs)
            table[s].append(row)
            log(json.dumps({"set": s, **row}))
    report["sets"] = table
    write_text_atomic(out / "recipe.json", json.dumps(report, indent=1, default=str))
    print(markdown(table))
    gen = {r["condition"]: r for r in table["generated"]}

    def frac(c: str) -> str:
        return f"{gen[c]['successes']}/{gen[c]['episodes']}"

    print(
        f"trained model: checker+constrained {frac('checker+constrained')}, checker+repair "
        f"{frac('checker+repair')}, checker {frac('checker')}, open loop {frac('open-loop')} "
        "(held-out generated tasks)"
    )
    return 0
