"""`gsr solve --format gsr-bench` on GSR-Bench configs, judged by the benchmark's validator rules.

For every config: its scene-graph message is written to a file, ``gsr solve --scene FILE --instruction
TASK_QUERY --format gsr-bench`` runs (in-process by default; ``--cli`` runs the real command), and the
printed commands are replayed under GSR-Bench's rules (:mod:`gsr.gsr_bench_rules`) from the config's
scene. A config counts as solved when the command succeeds, every command is accepted, and the
final graph satisfies the config's reference goal (the suite's goal for its query, any alternative).
The agent never sees the reference goal: ``gsr solve`` grounds the instruction itself.

    python benchmarks/bench_gsr_bench_solve.py                       # the 90 dev configs (shared data)
    python benchmarks/bench_gsr_bench_solve.py --generated 20        # the generated cells, 20 per cell
    python benchmarks/bench_gsr_bench_solve.py --cli --limit 5       # through the real `gsr solve` command
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gsr.benchmarks.scoring import score_task
from gsr.benchmarks.suites.gsr_bench import load_configs, task_from_config
from gsr.benchmarks.suites.gsr_bench_gen import generate_configs

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.gsr_bench_rules import replay
from gsr.reason.cli import solve_command
from gsr.resources import load_builtin_domain, shared_data_dir


def _solve_in_process(scene: Path, query: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = solve_command(scene, query, fmt="gsr-bench")
        except GSRError as exc:
            print(f"error: {exc}", file=sys.stderr)
            rc = 1
    return rc, out.getvalue(), err.getvalue()


def _solve_cli(scene: Path, query: str) -> tuple[int, str, str]:
    gsr = Path(sys.executable).with_name("gsr")
    cmd = [str(gsr), "solve", "--scene", str(scene), "--instruction", query, "--format", "gsr-bench"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    return done.returncode, done.stdout, done.stderr


def judge(config: dict[str, Any], cli: bool, folder: Path) -> dict[str, Any]:
    """Solve one config and judge the printed commands under the rules; a record of what happened."""
    task = task_from_config(config)
    scene = folder / f"{task.id}.json"
    scene.write_text(json.dumps(config["scene_graph"]), encoding="utf-8")
    start = time.perf_counter()
    rc, out, err = (_solve_cli if cli else _solve_in_process)(scene, task.instruction)
    seconds = time.perf_counter() - start
    record: dict[str, Any] = {
        "id": task.id,
        "query": task.instruction,
        "rc": rc,
        "seconds": round(seconds, 3),
    }
    if rc != 0:
        record.update(solved=False, why=(err.strip().splitlines() or ["no output"])[0][:200])
        return record
    commands = [line.strip() for line in out.splitlines() if line.strip()]
    checked = replay(graph_from_gsr_bench(config["scene_graph"]), commands)
    record["commands"] = len(commands)
    if not checked.ok:
        bad = checked.rejected
        record.update(solved=False, why=f"rejected '{bad.command}' ({bad.rule.value}): {bad.message}")
        return record
    domain = load_builtin_domain("tabletop")
    score = score_task(domain, task, state_from_graph(checked.graph, domain))
    record.update(solved=score.success, why="" if score.success else f"goal {score.satisfied}/{score.total}")
    return record


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, help="GSR-Bench YAML (default: the shared dev configs)")
    parser.add_argument("--generated", type=int, default=0, help="use N generated configs per cell instead")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit", type=int)
    parser.add_argument("--cli", action="store_true", help="run the real `gsr solve` command per config")
    parser.add_argument("--json", type=Path, help="write the per-config records here")
    args = parser.parse_args(argv)
    if args.generated:
        configs = generate_configs(seed=args.seed, per_cell=args.generated)
        name = f"generated ({args.generated} per cell, seed {args.seed})"
    else:
        path = args.source or shared_data_dir() / "gsr_bench" / "saved_configs_dev.yaml"
        if not path.is_file():
            print(f"error: {path}: no GSR-Bench configs (set --source or GSR_SHARED_DATA)", file=sys.stderr)
            return 2
        configs = load_configs(path)
        name = str(path)
    configs = configs[: args.limit] if args.limit else configs
    start, cpu = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory(prefix="gsr-bench-solve-") as tmp:
        records = [judge(c, args.cli, Path(tmp)) for c in configs]
    solved = sum(r["solved"] for r in records)
    print(f"{name}: {solved}/{len(records)} solved and accepted by GSR-Bench's rules "
          f"({'gsr solve CLI' if args.cli else 'in-process gsr solve'}, --format gsr-bench, grounder backend); "
          f"wall {time.perf_counter() - start:.1f} s, CPU {time.process_time() - cpu:.1f} s (this process)")  # fmt: skip
    why = Counter(r["why"].split(":")[0] for r in records if not r["solved"])
    for reason, n in why.most_common():
        print(f"  {n} x {reason}")
    for r in records:
        if not r["solved"]:
            print(f"  {r['id']}: {r['query']!r}: {r['why']}")
    if args.json:
        args.json.write_text(json.dumps(records, indent=1), encoding="utf-8")
    return 0 if solved == len(records) else 1


if __name__ == "__main__":
    sys.exit(main())
