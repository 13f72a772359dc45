"""The checker ablation's conditions and runs: each condition is one ``gsr bench run tasks`` call with a
trained model (open loop, checker, checker + repair, checker + constrained decoding), and the table
that compares them. Used by ``bench_training.py`` and by the trained-reasoner recipe
(:mod:`gsr.benchmarks.training_recipe`).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Any

CONDITIONS: dict[str, tuple[str, list[str]]] = {
    "open-loop": ("gsr.train.openloop:OpenLoopAgent", []),
    "checker": ("reasoner", ["max_repairs=0"]),
    "checker+repair": ("reasoner", ["max_repairs={repairs}"]),
    "checker+constrained": ("reasoner", ["max_repairs={repairs}", "constrained=true"]),
    "open-loop+constrained": ("gsr.train.openloop:OpenLoopAgent", ["constrained=true"]),
}
DEFAULT_CONDITIONS = ("open-loop", "checker", "checker+repair", "checker+constrained")


def gsr_command() -> list[str]:
    """How to call the gsr CLI from this interpreter (works without the console script on PATH)."""
    return [sys.executable, "-c", "from gsr.cli import main; main()"]


def run_condition(
    name: str, model: str, tasks: str, workers: int, max_steps: int, repairs: int
) -> dict[str, Any]:
    """One runner call; its results.json plus wall time and mean valid steps."""
    agent, opts = CONDITIONS[name]
    cmd = [
        *gsr_command(),
        "bench",
        "run",
        "tasks",
        "--tasks",
        tasks,
        "--agent",
        agent,
        "--agent-opt",
        f"backend=transformers:{model}",
        "--workers",
        str(workers),
        "--max-steps",
        str(max_steps),
        "--json",
    ]
    for opt in opts:
        cmd += ["--agent-opt", opt.format(repairs=repairs)]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if proc.returncode not in (0, 1):  # 1 = some episodes failed, which is a result
        raise SystemExit(f"{name}: runner exited {proc.returncode}: {proc.stderr.strip()[-2000:]}")
    try:
        results = json.loads(proc.stdout)
    except json.JSONDecodeError:
        raise SystemExit(f"{name}: runner printed no JSON: {proc.stderr.strip()[-2000:]}") from None
    episodes = results["tasks"]
    m = results["metrics"]
    return {
        "condition": name,
        "episodes": len(episodes),
        "successes": sum(1 for e in episodes if e["success"]),
        "success_rate": m["success_rate"],
        "executability": m["executability"],
        "mean_valid_steps": round(sum(e["valid"] for e in episodes) / max(1, len(episodes)), 2),
        "mean_proposed": round(sum(e["proposed"] for e in episodes) / max(1, len(episodes)), 2),
        "wall_seconds": round(wall, 1),
        "by_category": {k: v["success_rate"] for k, v in results["by_category"].items()},
    }


def markdown(table: dict[str, list[dict[str, Any]]]) -> str:
    """The ablation table: one row per condition, success / executability / valid steps per task set."""
    sets = list(table)
    head = "| condition | " + " | ".join(f"{s}: success | exec. | valid steps" for s in sets) + " |"
    lines = [head, "|---|" + "---:|---:|---:|" * len(sets)]
    for i, name in enumerate(r["condition"] for r in table[sets[0]]):
        cells = []
        for s in sets:
            r = table[s][i]
            cells.append(
                f"{100 * r['success_rate']:.0f}% ({r['successes']}/{r['episodes']}) | "
                f"{r['executability']:.2f} | {r['mean_valid_steps']:.1f}"
            )
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
