"""benchmarks/bench_ipc_language.py on a small collection built from the shipped IPC fixtures."""

from __future__ import annotations

import itertools
import json
import shutil
from pathlib import Path

import pytest
from gsr.benchmarks.bench_ipc_language import main, markdown, pick_problem, subprocess_row, summary

from tests.data_paths import PDDL


@pytest.fixture
def collection(tmp_path: Path) -> Path:
    root = tmp_path / "collection"
    blocks = root / "blocks"
    blocks.mkdir(parents=True)
    for name in ("domain.pddl", "probBLOCKS-4-0.pddl", "probBLOCKS-9-0.pddl"):
        shutil.copy(PDDL / "blocks" / name, blocks / name)
    # a per-problem domain file, as several IPC folders have (p01-domain.pddl beside p01.pddl)
    per = root / "miconic-per-problem"
    per.mkdir()
    shutil.copy(PDDL / "miconic-simpleadl" / "domain.pddl", per / "s1-0-domain.pddl")
    shutil.copy(PDDL / "miconic-simpleadl" / "s1-0.pddl", per / "s1-0.pddl")
    broken = root / "broken"
    broken.mkdir()
    (broken / "domain.pddl").write_text("(define (domain b) (:predicates (p)")
    (broken / "p01.pddl").write_text("(define (problem q) (:domain b) (:init) (:goal (p)))")
    (root / "no-problems").mkdir()
    return root


def test_picks_the_smallest_problem_and_its_domain_file(collection: Path) -> None:
    dom, prob = pick_problem(collection / "blocks", 0)
    assert (dom.name, prob.name) == ("domain.pddl", "probBLOCKS-4-0.pddl")
    assert pick_problem(collection / "blocks", 5)[1].name == "probBLOCKS-9-0.pddl"  # clamped to the last
    dom, prob = pick_problem(collection / "miconic-per-problem", 0)
    assert (dom.name, prob.name) == ("s1-0-domain.pddl", "s1-0.pddl")
    assert pick_problem(collection / "no-problems", 0) is None


def test_rows_load_plan_validate_and_a_broken_domain(collection: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "rows.json"
    assert main([str(collection), "--timeout", "20", "--save", str(out), "--markdown"]) == 0
    rows = {r["domain"]: r for r in json.loads(out.read_text())["rows"]}
    assert set(rows) == {"blocks", "miconic-per-problem", "broken"}  # a folder without problems is left out
    for name in ("blocks", "miconic-per-problem"):
        assert rows[name]["load"] and rows[name]["plan"] == "solved" and rows[name]["valid"] is True
        assert rows[name]["length"] > 0 and rows[name]["cpu"] > 0
        assert rows[name]["operators"] > 0 and rows[name]["ground_time"] >= 0
    assert rows["broken"]["load"] is False and "domain.pddl" in rows["broken"]["message"]
    assert "operators" not in rows["broken"]
    text = capsys.readouterr().out
    assert "domains 3: load 2, ground 2, plan 2 (limit 20 s), validate 2" in text
    ops = rows["blocks"]["operators"]
    assert (
        f"| blocks | probBLOCKS-4-0.pddl | yes | {rows['blocks']['ground_time']:.2f} ({ops}) | solved | yes |"
        in text
    )
    assert "| broken | p01.pddl | no | - | None | - |" in text
    assert [p.name for p in tmp_path.iterdir()] == ["collection", "rows.json"]  # written atomically


def test_an_absent_collection_is_skipped_with_one_line(tmp_path: Path, capsys) -> None:
    assert main([str(tmp_path / "absent")]) == 0
    assert capsys.readouterr().out.startswith("skipped:")


def test_markdown_and_summary_with_fd_columns() -> None:
    row = {"domain": "d", "problem": "p.pddl", "load": True, "plan": "timeout", "valid": None, "wall": 61.0}
    row["cpu"] = 30.5
    row["fd"] = {"status": "solved", "time": 1.5, "cpu": 1.25, "length": 7, "translated": True}
    row["fd"].update(translate_wall=0.5, operators=12)
    killed = {
        **row,
        "domain": "e",
        "plan": "solved",
        "valid": True,
        "length": 3,
        "operators": 9,
        "ground_time": 0.25,
    }
    killed["fd"] = {"status": "timeout", "time": 60.2, "cpu": None, "length": None, "translated": False}
    table = markdown([row, killed], fd=True).splitlines()
    assert table[2] == (
        "| d | p.pddl | yes | not finished | timeout | - | 61.00 / 30.50 | - | 0.50 (12) | solved | 1.50 / 1.25 | 7 |"
    )
    assert table[3] == (
        "| e | p.pddl | yes | 0.25 (9) | solved | yes | 61.00 / 30.50 | 3 | not finished | timeout | 60.20 / - | - |"
    )
    assert summary([row, killed], 60, fd=True).splitlines() == [
        "domains 2: load 2, ground 1, plan 1 (limit 60 s), validate 1",
        "Fast Downward translated 1, solved 1 of 2; GSR solved and validated 0 of those, and 1 FD did not solve",
    ]


def test_cpu_clock_stops_the_child_on_cpu_time_and_keeps_what_it_did(tmp_path: Path) -> None:
    # A task whose search cannot finish: 14 blocks to reverse with blind breadth-first search.
    blocks = [f"b{i}" for i in range(14)]
    on = " ".join(f"(on {a} {b})" for a, b in itertools.pairwise(blocks))
    goal = " ".join(f"(on {b} {a})" for a, b in itertools.pairwise(blocks))
    problem = tmp_path / "tower.pddl"
    problem.write_text(
        f"(define (problem tower) (:domain BLOCKS) (:objects {' '.join(blocks)})"
        f" (:init (handempty) (clear b0) (ontable b13) {on}) (:goal (and {goal})))"
    )
    row = subprocess_row(PDDL / "blocks" / "domain.pddl", problem, 2.0, "bfs", cpu=True)
    assert row["load"] is True and row["plan"] == "timeout" and row["message"] == "over 2 s CPU"
    assert row["operators"] > 0  # grounding finished before the limit and is reported
    assert 1.5 < row["cpu"] < 15  # stopped by its CPU time (plus start-up), not by the wall limit
