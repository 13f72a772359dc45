"""How often the grounder recovers the dataset generator's goals from its instructions.

``python -m gsr.language.measure --samples 14000 --seed 7`` generates the rows that
``gsr datagen --samples 14000 --seed 7`` writes (same shards, in memory) — or reads a dataset with
``--data DIR`` — takes every ``goal_interpretation`` row (an instruction, the start graph and the
reference PDDL goal) and grounds the instruction. Each row is one of:

* ``equivalent``: the grounded goal has the reference goal's ground DNF (gsr.language.equivalence);
* ``wrong_goal``: a goal, but a different one;
* ``unknown_word``: a word outside the lexicon (GroundingError.unknown_words);
* ``not_understood``: known words the grammar does not accept;
* ``ambiguous``: a reference (or the readings) could mean several things — the grounder refuses to
  guess; whether the graph really leaves it open is judged by reading the examples;
* ``no_match`` / ``other_error``: a reference that matches nothing, any other GroundingError.

Prints a JSON report (counts, fractions, the most frequent unknown words, a few examples per kind).
"""

from __future__ import annotations

import argparse
import glob
import json
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from gsr.datagen.generate import generate_shard
from gsr.datagen.runner import RunConfig
from gsr.datagen.schema import decode
from gsr.errors import GSRError
from gsr.language import GroundingError, ground
from gsr.language.equivalence import equivalent_goals
from gsr.language.paraphrase import Item, load_items, same_goal_states, scene_graph
from gsr.pddl.parser import parse_formula
from gsr.pddl.writer import write_formula

KINDS = ("equivalent", "wrong_goal", "unknown_word", "not_understood", "ambiguous", "no_match", "other_error")


def generated_rows(samples: int, seed: int) -> Iterator[dict[str, Any]]:
    """The goal_interpretation rows of ``gsr datagen --samples N --seed S`` (default shard size), in order."""
    cfg = RunConfig(Path("."), samples, seed)
    for shard in range(cfg.n_shards):
        result = generate_shard(seed, shard, cfg.shard_rows(shard))
        for split in ("train", "val", "test"):
            yield from (r for r in result.rows[split] if r["type"] == "goal_interpretation")


def dataset_rows(data: Path) -> Iterator[dict[str, Any]]:
    """The goal_interpretation rows of a dataset directory written by ``gsr datagen``."""
    files = sorted(glob.glob(str(data / "data" / "*" / "*.jsonl")))
    if not files:
        raise GSRError(f"{data}: no data/*/*.jsonl files (not a gsr datagen output directory)")
    for path in files:
        with open(path, encoding="utf-8") as fh:
            for n, line in enumerate(fh, 1):
                try:
                    row = json.loads(line)
                except json.JSONDecodeError as exc:
                    raise GSRError(f"{path}:{n}: not JSON: {exc.msg}") from None
                if row.get("type") == "goal_interpretation":
                    yield row


def classify(instruction: str, graph, reference, equivalent=None) -> tuple[str, str]:
    """(kind, detail) for one instruction against its reference goal formula.

    ``equivalent(a, b, graph)`` decides goal equivalence (default: equal ground DNFs).
    """
    equivalent = equivalent or equivalent_goals

    try:
        goal = ground(instruction, graph)
    except GroundingError as exc:
        if exc.unknown_words:
            return "unknown_word", " ".join(exc.unknown_words)
        msg = exc.message
        if "ambiguous" in msg or "readings with different goals" in msg or "several levels" in msg:
            return "ambiguous", msg
        if msg.startswith("cannot understand"):
            return "not_understood", msg
        if msg.startswith("no object in the scene matches"):
            return "no_match", msg
        return "other_error", msg
    if equivalent(goal.formula, reference, graph):
        return "equivalent", ""
    return "wrong_goal", write_formula(goal.formula)


def measure(rows: Iterator[dict[str, Any]], limit: int | None = None, examples: int = 5) -> dict[str, Any]:
    """Classify up to ``limit`` rows; the report (counts, fractions, unknown words, examples)."""
    counts: Counter[str] = Counter()
    words: Counter[str] = Counter()
    shown: dict[str, list[dict[str, str]]] = {k: [] for k in KINDS}
    n = 0
    for row in rows:
        if limit is not None and n >= limit:
            break
        n += 1
        _, inp, out = decode(row)
        kind, detail = classify(inp.instruction, inp.graph, parse_formula(out.goal, f"row {row['id']}"))
        counts[kind] += 1
        if kind == "unknown_word":
            words.update(detail.split())
        if kind != "equivalent" and len(shown[kind]) < examples:
            shown[kind].append(
                {"row": row["id"], "instruction": inp.instruction, "reference": out.goal, "got": detail}
            )
    return {
        "rows": n,
        "counts": {k: counts[k] for k in KINDS},
        "fractions": {k: round(counts[k] / n, 4) if n else 0.0 for k in KINDS},
        "unknown_words": dict(words.most_common(20)),
        "examples": {k: v for k, v in shown.items() if v},
    }


def classify_item(item: Item) -> tuple[str, str]:
    """(kind, detail) of one paraphrase item (gsr.language.paraphrase) on its scene."""
    graph = scene_graph(item.scene)
    reference = parse_formula(item.goal, f"{item.part}: {item.say!r}")
    return classify(item.say, graph, reference, equivalent=same_goal_states)


def run_items(items: list[Item]) -> Iterator[tuple[Item, str, str]]:
    """Each item with its outcome kind and detail."""
    for item in items:
        kind, detail = classify_item(item)
        yield item, kind, detail


def measure_paraphrase(parts: dict[str, int]) -> dict[str, Any]:
    """The paraphrase benchmark (gsr.language.paraphrase): a report per part, examples only when asked."""
    out: dict[str, Any] = {}
    for part, examples in parts.items():
        counts: Counter[str] = Counter()
        shown: dict[str, list[dict[str, str]]] = {k: [] for k in KINDS}
        items = load_items(part)
        for item, kind, detail in run_items(items):
            counts[kind] += 1
            if kind != "equivalent" and len(shown[kind]) < examples:
                shown[kind].append(
                    {"scene": item.scene, "instruction": item.say, "reference": item.goal, "got": detail}
                )
        n = len(items)
        out[part] = {
            "rows": n,
            "equivalent": round(counts["equivalent"] / n, 4) if n else 0.0,
            "counts": {k: counts[k] for k in KINDS},
            "examples": {k: v for k, v in shown.items() if v},
        }
    return out


def main(argv: list[str] | None = None) -> int:
    """Command line: print the JSON report; exit 1 with a one-line message on bad input."""
    ap = argparse.ArgumentParser(prog="python -m gsr.language.measure", description=__doc__.split("\n")[0])
    src = ap.add_mutually_exclusive_group()
    src.add_argument("--data", type=Path, help="a gsr datagen output directory")
    src.add_argument("--samples", type=int, default=14000, help="rows to generate (as gsr datagen --samples)")
    ap.add_argument("--seed", type=int, default=7, help="generator seed (as gsr datagen --seed)")
    ap.add_argument("--limit", type=int, default=None, help="classify at most this many instructions")
    ap.add_argument("--examples", type=int, default=5, help="examples shown per failure kind")
    ap.add_argument(
        "--suite",
        choices=("datagen", "paraphrase"),
        default="datagen",
        help="datagen: the dataset generator's instructions (default); paraphrase: the hand-written benchmark",
    )
    ap.add_argument(
        "--part",
        choices=("dev", "heldout", "both"),
        default="both",
        help="paraphrase part(s) to score (examples of failures are shown for the dev part only)",
    )
    args = ap.parse_args(argv)
    if args.suite == "paraphrase":
        try:
            names = ["dev", "heldout"] if args.part == "both" else [args.part]
            # failures are listed for the development part only: the kept-apart part reports counts
            parts = {name: args.examples if name == "dev" else 0 for name in names}
            report = {"suite": "paraphrase", "parts": measure_paraphrase(parts)}
        except GSRError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        print(json.dumps(report, indent=1))
        return 0
    try:
        rows = dataset_rows(args.data) if args.data else generated_rows(args.samples, args.seed)
        report = measure(rows, args.limit, args.examples)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    report["source"] = str(args.data) if args.data else {"samples": args.samples, "seed": args.seed}
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
