"""Benchmark reports: results.json, report.md and report.html (with matplotlib plots when installed).

Every file is written atomically (a temporary file in the same folder, then renamed), so an
interrupted run never leaves a truncated or half-written results file behind.
"""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path
from typing import Any

from gsr.benchmarks.metrics import by_cell, grouped, summarize

from gsr.episode import OUTCOMES, EpisodeResult
from gsr.io import write_text_atomic

_COLS = ("episodes", "success_rate", "score", "executability", "goal_recall", "mean_steps", "mean_time")


def results_document(results: list[EpisodeResult], suite: str, agent: str, **meta: Any) -> dict[str, Any]:
    """The results.json document: overall metrics, groups and one row per episode."""
    overall = summarize(results)
    return {
        "suite": suite,
        "agent": agent,
        **meta,
        "success_rate": overall.get("success_rate", 0.0),
        "metrics": overall,
        "by_category": grouped(results, "category"),
        "by_level": grouped(results, "level"),
        "by_cell": by_cell(results),
        "tasks": [r.to_dict() for r in results],
    }


def _table(rows: dict[str, dict[str, Any]], first: str) -> list[str]:
    head = [first, *_COLS, *OUTCOMES]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name, m in rows.items():
        cells = [
            name,
            *(str(m.get(c, "")) for c in _COLS),
            *(str(m.get("outcomes", {}).get(o, 0)) for o in OUTCOMES),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def markdown_report(doc: dict[str, Any]) -> str:
    """The Markdown report: overall, per category, per level, per cell, and the failures."""
    m = doc["metrics"]
    lines = [
        f"# Benchmark report: {doc['suite']} / agent {doc['agent']}",
        "",
        f"Seed {doc.get('seed')}, trials {doc.get('trials')}, backend {doc.get('backend')}.",
        "",
        f"**Success rate {m.get('success_rate', 0):.1%}**, score (partial credit) {m.get('score', 0):.3f}, "
        f"executability {m.get('executability', 0):.3f}, goal recall {m.get('goal_recall', 0):.3f}, "
        f"mean steps {m.get('mean_steps')}, plan length vs reference {m.get('length_vs_reference')}.",
        "",
        "## Overall",
        *_table({"all": m}, "set"),
        "",
        "## By category",
        *_table(doc["by_category"], "category"),
        "",
        "## By level",
        *_table(doc["by_level"], "level"),
        "",
        "## By cell",
        *_table(doc["by_cell"], "cell"),
        "",
    ]
    lines.extend(_observation_lines(doc))
    failures = [t for t in doc["tasks"] if not t["success"]]
    lines.append(f"## Failures ({len(failures)})")
    lines.extend(f"- `{t['id']}` (trial {t['trial']}): {t['outcome']}: {t['reason']}" for t in failures[:200])
    lines.extend(_frame_lines(doc))
    return "\n".join(lines) + "\n"


def _observation_lines(doc: dict[str, Any]) -> list[str]:
    """Physical runs: what the agent observed, and how its final belief compares with the world."""
    if not doc.get("physical"):
        return []
    tasks = doc["tasks"]
    if not doc.get("perceive"):
        return ["Physical execution (PyBullet); the agent observed the simulator's ground-truth graph.", ""]
    rows = [t for t in tasks if t.get("perceived_success") is not None]
    both = sum(t["success"] and t["perceived_success"] for t in rows)
    believed = sum(t["perceived_success"] and not t["success"] for t in rows)
    missed = sum(t["success"] and not t["perceived_success"] for t in rows)
    return [
        "Physical execution (PyBullet); the agent observed **perceived** scene graphs (cameras + perception, "
        "the known map, the gripper, object permanence). Success is judged on the simulator's ground truth.",
        "",
        f"Goal held in the world and in the agent's perceived graph: {both}/{len(rows)}; "
        f"only in the perceived graph (perception believed a goal the world lacks): {believed}; "
        f"only in the world (perception missed it): {missed}.",
        "",
    ]


def _frame_lines(doc: dict[str, Any]) -> list[str]:
    """Links to the saved RGB frames (paths relative to the report's folder)."""
    rows = [t for t in doc.get("tasks", []) if isinstance(t, dict) and t.get("frames")]
    if not rows:
        return []
    lines = ["", f"## Frames ({len(rows)} episodes: first, middle and last RGB frame)"]
    for t in rows:
        images = " ".join(f"![{t['id']} frame {k}]({path})" for k, path in enumerate(t["frames"]))
        lines.append(
            f"- `{t['id']}` (trial {t['trial']}, {'success' if t['success'] else t['outcome']}): {images}"
        )
    return lines


def _frame_html(doc: dict[str, Any]) -> str:
    """The saved frames as <img> rows, one per episode."""
    rows = [t for t in doc.get("tasks", []) if isinstance(t, dict) and t.get("frames")]
    if not rows:
        return ""
    parts = ["<h2>Frames</h2>"]
    for t in rows:
        caption = html.escape(
            f"{t['id']} (trial {t['trial']}): {'success' if t['success'] else t['outcome']}"
        )
        imgs = "".join(f'<img alt="frame" src="{html.escape(p, quote=True)}"/>' for p in t["frames"])
        parts.append(f"<figure>{imgs}<figcaption>{caption}</figcaption></figure>")
    return "".join(parts)


def _plots(doc: dict[str, Any]) -> list[str]:
    """Base64 PNGs: success rate per category and the outcome classes (empty without matplotlib)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    out = []
    cats = doc["by_category"]
    fig, ax = plt.subplots(figsize=(7, 3.2))
    ax.barh(list(cats), [c["success_rate"] for c in cats.values()], color="#4477aa")
    ax.set_xlim(0, 1)
    ax.set_xlabel("success rate")
    ax.set_title(f"{doc['suite']} / {doc['agent']}: success per category")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    out.append(base64.b64encode(buf.getvalue()).decode())
    outcomes = doc["metrics"].get("outcomes", {})
    fig, ax = plt.subplots(figsize=(7, 2.6))
    palette = ["#228833", "#ccbb44", "#ee6677", "#aa3377", "#66ccee", "#4477aa", "#bbbbbb"]
    ax.bar(list(outcomes), list(outcomes.values()), color=palette[: len(outcomes)])
    ax.set_ylabel("episodes")
    ax.set_title("GSR-Bench outcome classes" if doc["suite"] != "delivery" else "delivery outcomes")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    out.append(base64.b64encode(buf.getvalue()).decode())
    return out


def html_report(doc: dict[str, Any], markdown: str) -> str:
    """A self-contained HTML page: the Markdown tables as preformatted text plus embedded plots."""
    plots = _plots(doc)
    imgs = "".join(f'<img alt="plot" src="data:image/png;base64,{p}"/>' for p in plots)
    note = "" if plots else "<p><em>plots need matplotlib (pip install matplotlib)</em></p>"
    return (
        "<!doctype html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(doc['suite'])} / {html.escape(doc['agent'])}</title></head><body>"
        f"{imgs}{note}<pre>{html.escape(markdown)}</pre>{_frame_html(doc)}</body></html>\n"
    )


def write_reports(out_dir: str | Path, doc: dict[str, Any], markdown: str | None = None) -> list[Path]:
    """Write results.json, report.md and report.html into ``out_dir`` (atomically); their paths.

    ``markdown`` replaces the default report text (an episode suite's own tables)."""
    out = Path(out_dir)
    md = markdown if markdown is not None else markdown_report(doc)
    paths = [out / "results.json", out / "report.md", out / "report.html"]
    write_text_atomic(paths[0], json.dumps(doc, indent=2) + "\n")
    write_text_atomic(paths[1], md)
    write_text_atomic(paths[2], html_report(doc, md))
    return paths
