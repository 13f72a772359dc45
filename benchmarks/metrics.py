"""Aggregate metrics over episode results: overall, per category and per level."""

from __future__ import annotations

import statistics
from collections.abc import Iterable
from typing import Any

from gsr.episode import OUTCOMES, EpisodeResult


def summarize(results: Iterable[EpisodeResult]) -> dict[str, Any]:
    """Success rate, mean score (partial credit), executability, goal-condition recall, steps, time, outcomes."""
    rs = list(results)
    n = len(rs)
    if not n:
        return {"episodes": 0}
    proposed = sum(r.proposed for r in rs)
    valid = sum(r.valid for r in rs)
    ratios = [
        r.steps / r.reference_steps for r in rs if r.success and r.reference_steps and r.reference_steps > 0
    ]
    succ_steps = [r.steps for r in rs if r.success]
    out: dict[str, Any] = {
        "episodes": n,
        "success_rate": round(sum(r.success for r in rs) / n, 4),
        "score": round(statistics.fmean(r.score for r in rs), 4),
        "executability": round(valid / proposed, 4) if proposed else 1.0,
        "goal_recall": round(statistics.fmean(r.recall for r in rs), 4),
        "mean_steps": round(statistics.fmean(r.steps for r in rs), 2),
        "mean_steps_success": round(statistics.fmean(succ_steps), 2) if succ_steps else None,
        "length_vs_reference": round(statistics.fmean(ratios), 4) if ratios else None,
        "mean_time": round(statistics.fmean(r.time for r in rs), 4),
        "total_time": round(sum(r.time for r in rs), 2),
        "outcomes": {o: sum(r.outcome == o for r in rs) for o in OUTCOMES},
    }
    refs = [r.reference_steps for r in rs if r.reference_steps]
    if refs:
        out["mean_reference_steps"] = round(statistics.fmean(refs), 2)
    return out


def grouped(results: Iterable[EpisodeResult], key: str) -> dict[str, dict[str, Any]]:
    """:func:`summarize` per value of ``key`` (``category``, ``level`` or ``suite``), in first-seen order."""
    groups: dict[str, list[EpisodeResult]] = {}
    for r in results:
        groups.setdefault(str(getattr(r, key) or "-"), []).append(r)
    return {k: summarize(v) for k, v in groups.items()}


def cell_key(r: EpisodeResult) -> str:
    """``category / level`` (the GSR-Bench cell)."""
    return f"{r.category} / {r.level}" if r.level else r.category


def by_cell(results: Iterable[EpisodeResult]) -> dict[str, dict[str, Any]]:
    """:func:`summarize` per category x level."""
    groups: dict[str, list[EpisodeResult]] = {}
    for r in results:
        groups.setdefault(cell_key(r), []).append(r)
    return {k: summarize(v) for k, v in groups.items()}
