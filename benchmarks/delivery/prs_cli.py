"""``gsr delivery prs``: run the PRS benchmark offline and write results, a PRS submission and a report.

Writes ``OUT/results.json`` (summary + one record per task), ``OUT/prs_submission.json`` (PRS's result
format keyed by task id) and ``OUT/report.html`` (metrics, failure reasons, floor maps with the robot's
path, the object and the person for a few tasks). All files are written atomically, after the run.
"""

from __future__ import annotations

import html
import json
import sys
from collections import Counter
from pathlib import Path

from gsr.benchmarks.delivery.building.prs import load_station
from gsr.benchmarks.delivery.prs_run import SPLITS, run_prs, run_prs_crossfit

from gsr.errors import GSRError
from gsr.io import write_text_atomic

MAP_TASKS = 6  # tasks drawn on floor maps in the report (failures first)


def prs_command(
    data: Path,
    tasks: Path,
    out: Path,
    workers: int = 1,
    captions: str = "dev",
    crossfit: int = 0,
    calibration: str = "auto",
    split: str = "position",
) -> int:
    """Run, write the three files, print the PRS metrics; 1 with a one-line message on bad input.

    ``crossfit`` K >= 2: the honest estimate on a task file that is also the calibration/caption source
    (each of K folds runs on a station calibrated, with captions built, from the other folds); ``split``
    says how the tasks are folded (``prs_run.SPLITS``: position, person or object)."""
    if workers < 1 or crossfit < 0 or crossfit == 1:
        print("error: --workers must be >= 1 and --crossfit 0 (off) or >= 2", file=sys.stderr)
        return 1
    if split not in SPLITS:
        print(f"error: --split must be one of {', '.join(SPLITS)}, not {split!r}", file=sys.stderr)
        return 1
    if crossfit and workers > 1:
        print("error: --crossfit runs its folds in one process; leave --workers at 1", file=sys.stderr)
        return 1
    try:
        if crossfit:
            run = run_prs_crossfit(data, tasks, crossfit, split, captions)
        else:
            run = run_prs(data, tasks, workers=workers, captions=captions, calibration=calibration)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    try:
        out.mkdir(parents=True, exist_ok=True)
        write_text_atomic(
            out / "results.json", json.dumps({"summary": run["summary"], "tasks": run["records"]}, indent=1)
        )
        write_text_atomic(out / "prs_submission.json", json.dumps(run["submission"], indent=1))
        write_text_atomic(out / "report.html", render_report(run, data))
    except OSError as exc:
        print(f"error: {out}: cannot write: {exc.strerror}", file=sys.stderr)
        return 1
    s = run["summary"]
    print(
        f"PRS delivery, {s['tasks']} tasks: Task SR {s['Task SR']:.3f}, Object Manipulation SR "
        f"{s['Object Manipulation SR']:.3f} (exact object {s['grasp_exact']:.3f}), Human Search SR "
        f"{s['Human Search SR']:.3f}, Time Used {s['Time Used']:.2f} min; {s['wall_s']:.1f} s wall"
    )
    print(
        f"  (Task SR by the simulator rule; PRS's eval.py as published reports Task SR "
        f"{s['Task SR (eval.py)']:.3f}: it never sets object_find)"
    )
    for reason, n in sorted(s["failure_reasons"].items(), key=lambda kv: -kv[1]):
        print(f"  {n:4d}  {reason}")
    print(f"wrote {out / 'results.json'}, {out / 'prs_submission.json'}, {out / 'report.html'}")
    return 0


def _floor_svg(grid, trace: dict, cell_px: int = 3) -> str:
    """An SVG of one floor: free cells light, the robot's path, object (square) and person (circle)."""
    rows, cols = grid.shape
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{cols * cell_px}" height="{rows * cell_px}" '
        f'style="background:#333">'
    ]
    for i in range(rows):
        j = 0
        while j < cols:
            if grid[i, j] != 0:
                k = j
                while k < cols and grid[i, k] != 0:
                    k += 1
                parts.append(
                    f'<rect x="{j * cell_px}" y="{i * cell_px}" width="{(k - j) * cell_px}" height="{cell_px}" '
                    f'fill="#eee"/>'
                )
                j = k
            else:
                j += 1
    pts = " ".join(f"{c * cell_px + cell_px / 2},{r * cell_px + cell_px / 2}" for _, r, c in trace["path"])
    parts.append(f'<polyline points="{pts}" fill="none" stroke="#1565c0" stroke-width="1.5"/>')
    if trace.get("object"):
        _, (r, c) = trace["object"]
        parts.append(
            f'<rect x="{c * cell_px - 3}" y="{r * cell_px - 3}" width="7" height="7" fill="#e65100"/>'
        )
    if trace.get("person"):
        _, (r, c) = trace["person"]
        parts.append(f'<circle cx="{c * cell_px + 1}" cy="{r * cell_px + 1}" r="4" fill="#2e7d32"/>')
    parts.append("</svg>")
    return "".join(parts)


def render_report(run: dict, data: Path) -> str:
    """The HTML report: metrics, a failure-reason table and floor maps of a few tasks."""
    s = run["summary"]
    rec = run["records"]
    station = load_station(data, None)
    rows = "".join(
        f"<tr><td>{html.escape(k)}</td><td>{v:.3f}</td></tr>"
        for k, v in s.items()
        if isinstance(v, float) and k not in ("wall_s", "cpu_s_main")
    )
    reasons = Counter(r["failure_reason"] for r in rec if r["failure_reason"])
    reason_rows = (
        "".join(f"<tr><td>{html.escape(k)}</td><td>{n}</td></tr>" for k, n in reasons.most_common())
        or "<tr><td>(none)</td><td>0</td></tr>"
    )
    picked = [r for r in rec if not r["success"]][: MAP_TASKS // 2]
    picked += [r for r in rec if r["success"]][: MAP_TASKS - len(picked)]
    maps = []
    for r in picked:
        trace = run["traces"][r["task_id"]]
        level = trace["path"][0][0] if trace["path"] else 0
        grid = station.floors[level].grid
        maps.append(
            f"<figure><figcaption>{html.escape(r['task_id'])}: "
            f"{'success' if r['success'] else html.escape(r['failure_reason'])}, "
            f"{r['sim_minutes']:.1f} sim min (floor {level}; path blue, object orange, person green)"
            f"</figcaption>{_floor_svg(grid, trace)}</figure>"
        )
    return (
        "<!doctype html><meta charset='utf-8'><title>PRS delivery (offline)</title>"
        "<style>body{font-family:sans-serif;margin:2em}td{padding:2px 10px}</style>"
        f"<h1>PRS delivery benchmark, offline environment</h1><p>{s['tasks']} tasks; captions: "
        f"{html.escape(str(s['captions']))}; wall {s['wall_s']} s with {s['workers']} worker(s).</p>"
        f"<h2>Metrics (PRS rules)</h2><table>{rows}</table>"
        f"<h2>Failures by reason</h2><table><tr><th>reason</th><th>tasks</th></tr>{reason_rows}</table>"
        f"<h2>Floor maps</h2>{''.join(maps)}"
    )
