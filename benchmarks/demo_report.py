"""The demo's output folder: pictures, plan with checks, JSON summary and report.html — written atomically.

Everything is first written to a sibling temporary folder which then replaces ``out`` in one rename, so
an interrupted demo never leaves a half-written report behind.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from dataclasses import dataclass, field
from html import escape
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class DemoRecord:
    """What the demo did, step by step, for the report."""

    task: str
    instruction: str
    goal: str = ""
    perceived: bool = True
    stages: list[tuple[str, float, str]] = field(default_factory=list)  # (stage, seconds, note)
    steps: list[dict[str, Any]] = field(default_factory=list)  # step, check message, skill result
    verified: bool = False
    verdict: str = ""
    images: dict[str, np.ndarray] = field(default_factory=dict)  # name -> RGB
    svgs: dict[str, str] = field(default_factory=dict)  # name -> SVG text
    graphs: dict[str, Any] = field(default_factory=dict)  # name -> scene-graph JSON data


def _png(rgb: np.ndarray, path: Path) -> None:
    from PIL import Image

    Image.fromarray(np.ascontiguousarray(rgb[..., :3]).astype(np.uint8)).save(path)


def _html(rec: DemoRecord) -> str:
    rows = "\n".join(
        f"<tr><td>{i}</td><td><code>{escape(s['step'])}</code></td><td>{escape(s['check'])}</td>"
        f"<td class='{'ok' if s['executed'] else 'bad'}'>{escape(s['execution'])}</td></tr>"
        for i, s in enumerate(rec.steps, 1)
    )
    stages = "\n".join(
        f"<tr><td>{escape(name)}</td><td>{seconds:.2f} s</td><td>{escape(note)}</td></tr>"
        for name, seconds, note in rec.stages
    )
    pictures = "".join(
        f"<figure><img src='{name}.png' alt='{name}'><figcaption>{name.replace('_', ' ')}</figcaption></figure>"
        for name in rec.images
    )
    graphs = "".join(
        f"<figure><img src='{name}.svg' alt='{name}'><figcaption>{name.replace('_', ' ')}</figcaption></figure>"
        for name in rec.svgs
    )
    verdict_class = "ok" if rec.verified else "bad"
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>GSR demo: {escape(rec.instruction)}</title>
<style>
body {{ font-family: Helvetica, Arial, sans-serif; margin: 2em; max-width: 1200px; color: #222; }}
figure {{ display: inline-block; margin: 0 1em 1em 0; vertical-align: top; }}
figure img {{ max-width: 560px; border: 1px solid #ccc; }}
table {{ border-collapse: collapse; margin-bottom: 1.5em; }}
td, th {{ border: 1px solid #ccc; padding: 4px 8px; text-align: left; vertical-align: top; }}
.ok {{ color: #1b7f2a; font-weight: bold; }} .bad {{ color: #b3261e; font-weight: bold; }}
code {{ background: #f3f3f3; padding: 1px 3px; }}
</style></head><body>
<h1>GSR end-to-end demo</h1>
<p><b>Instruction:</b> {escape(rec.instruction)}<br><b>Task:</b> {escape(rec.task)}<br>
<b>Grounded goal:</b> <code>{escape(rec.goal)}</code><br>
<b>Scene graphs from:</b> {"perception of rendered RGB-D (instance masks from the simulator)" if rec.perceived else "simulator ground truth"}</p>
<p class="{verdict_class}">{escape(rec.verdict)}</p>
<h2>Camera (before / after)</h2>{pictures}
<h2>Scene graph (before / after)</h2>{graphs}
<h2>Plan: each step checked, then executed</h2>
<table><tr><th>#</th><th>step</th><th>check</th><th>execution</th></tr>{rows}</table>
<h2>Stages</h2><table><tr><th>stage</th><th>time</th><th>note</th></tr>{stages}</table>
<p>Files: <a href="plan.txt">plan.txt</a>, <a href="summary.json">summary.json</a>,
<a href="graph_before.json">graph_before.json</a>, <a href="graph_after.json">graph_after.json</a>.</p>
</body></html>
"""


def write_report(rec: DemoRecord, out: Path) -> Path:
    """Write the demo folder ``out`` (replacing an older one) and return the path of report.html."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}-", dir=out.parent))
    tmp.chmod(0o755)  # mkdtemp makes it private; the report is meant to be shared
    try:
        for name, rgb in rec.images.items():
            _png(rgb, tmp / f"{name}.png")
        for name, svg in rec.svgs.items():
            (tmp / f"{name}.svg").write_text(svg, encoding="utf-8")
        for name, data in rec.graphs.items():
            (tmp / f"{name}.json").write_text(json.dumps(data, indent=2), encoding="utf-8")
        plan_lines = [f"; {rec.instruction}", f"; goal: {rec.goal}"]
        for s in rec.steps:
            plan_lines += [s["step"], f";   check: {s['check']}", f";   execution: {s['execution']}"]
        (tmp / "plan.txt").write_text("\n".join(plan_lines) + "\n", encoding="utf-8")
        summary = {
            "task": rec.task,
            "instruction": rec.instruction,
            "goal": rec.goal,
            "perceived": rec.perceived,
            "verified": rec.verified,
            "verdict": rec.verdict,
            "steps": rec.steps,
            "stages": [{"stage": n, "seconds": round(t, 3), "note": note} for n, t, note in rec.stages],
        }
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
        (tmp / "report.html").write_text(_html(rec), encoding="utf-8")
        if out.exists():
            old = out.with_name(f".{out.name}-old")
            shutil.rmtree(old, ignore_errors=True)
            out.rename(old)
            tmp.rename(out)
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out / "report.html"
