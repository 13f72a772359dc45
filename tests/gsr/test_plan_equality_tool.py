"""The same-output check of planner changes (gsr.benchmarks.planner_equality): its digest sees a
changed operator, initial state or goal, and its comparison names the problems that differ."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from gsr.benchmarks.planner_equality import compare, main, task_digest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task

BLOCKS = Path(__file__).resolve().parents[1] / "fixtures" / "pddl" / "blocks"


def _task():
    domain = load_domain(BLOCKS / "domain.pddl")
    return ground_task(domain, load_problem(BLOCKS / "probBLOCKS-4-0.pddl", domain))


def test_digest_is_stable_and_sees_changes():
    task = _task()
    digest = task_digest(task)
    assert digest == task_digest(_task())
    assert digest["operators"] == len(task.ops) and digest["atoms"] == len(task.atoms)
    op = task.ops[3]
    task.ops[3] = dataclasses.replace(op, add=(*op.add, op.delete[0]) if op.delete else (0,))
    assert task_digest(task)["hash"] != digest["hash"]
    task.ops[3] = op
    task.init ^= 1
    assert task_digest(task)["hash"] != digest["hash"]
    task.init ^= 1
    task.goals = [(p[:-1], n) for p, n in task.goals]
    assert task_digest(task)["hash"] != digest["hash"]


def test_compare_names_differences_and_ignores_times():
    old = {
        "grounding": {"a": {"hash": "x", "operators": 1, "atoms": 2, "cpu_s": 0.1}},
        "plans": {"a": {"status": "solved", "expanded": 3, "steps": ["(s)"]}},
    }
    same = json.loads(json.dumps(old))
    same["grounding"]["a"]["cpu_s"] = 9.0
    assert compare(same, old) == []
    other = json.loads(json.dumps(old))
    other["plans"]["a"]["steps"] = ["(t)"]
    other["grounding"]["b"] = {"hash": "y", "operators": 1, "atoms": 1}
    assert compare(other, old) == ["grounding b: only in new", "plans a: differs"]


def test_main_reports_an_unreadable_reference(tmp_path, capsys, monkeypatch):
    import gsr.benchmarks.planner_equality as tool

    monkeypatch.setattr(tool, "collect", lambda ipc=True, plans=True: {"grounding": {}, "plans": {}})
    code = main(["--out", str(tmp_path / "new.json"), "--compare", str(tmp_path / "missing.json")])
    assert code == 2
    assert "cannot read" in capsys.readouterr().err
