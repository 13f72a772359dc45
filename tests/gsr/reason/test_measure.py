"""The measurement entry points on real LIBERO files (a few tasks, grounder backend)."""

from __future__ import annotations

import json

from gsr.reason.cases import libero_cases, split_cases
from gsr.reason.measure import main, run_cases, summary
from gsr.reason.tiny_model import random_goals, trace_pairs


def test_grounder_solves_libero_tasks(libero_dir, capsys):
    assert main([str(libero_dir / "libero_10"), "--limit", "3", "--mode", "hybrid"]) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["tasks"] == 3 and out["success"] == 3 and out["bench_goal"] == 3 and out["rejections"] == 0


def test_given_goal_rows_and_summary(libero_dir):
    cases = libero_cases(libero_dir / "libero_goal")[:2]
    rows = run_cases(cases, "grounder", "goal", given_goal=True)
    assert all(r["bench_goal"] and r["planner_steps"] == r["steps"] for r in rows)
    assert summary(rows)["tasks"] == 2


def test_training_pairs_are_checked_traces(libero_dir, domain):
    from gsr.reason import parse_first_step

    cases = split_cases(libero_cases(libero_dir / "libero_10"), "even")[:2]
    assert [c[0] for c in cases] == sorted(c[0] for c in cases)
    pairs = trace_pairs(cases)
    assert pairs and all(p.endswith("Next step:\n") for p, _ in pairs)
    assert all(parse_first_step(a).claims_effects for _, a in pairs)
    goals = random_goals(cases[0][1], 3, seed=1)
    assert goals == random_goals(cases[0][1], 3, seed=1) and len(goals) == 3
