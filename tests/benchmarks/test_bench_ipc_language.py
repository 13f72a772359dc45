"""benchmarks/bench_ipc_language.py on a small collection built from the shipped IPC fixtures."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from gsr.benchmarks.bench_ipc_language import main, markdown, pick_problem

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
    assert rows["broken"]["load"] is False and "domain.pddl" in rows["broken"]["message"]
    text = capsys.readouterr().out
    assert "domains 3: load 2, plan 2 (limit 20 s), validate 2" in text
    assert "| blocks | probBLOCKS-4-0.pddl | yes | solved | yes |" in text
    assert [p.name for p in tmp_path.iterdir()] == ["collection", "rows.json"]  # written atomically


def test_an_absent_collection_is_skipped_with_one_line(tmp_path: Path, capsys) -> None:
    assert main([str(tmp_path / "absent")]) == 0
    assert capsys.readouterr().out.startswith("skipped:")


def test_markdown_with_fd_columns() -> None:
    row = {"domain": "d", "problem": "p.pddl", "load": True, "plan": "timeout", "valid": None, "wall": 61.0}
    row["cpu"] = 30.5
    row["fd"] = {"status": "solved", "time": 1.5, "cpu": 1.25, "length": 7}
    killed = {**row, "domain": "e", "plan": "solved", "valid": True, "length": 3}
    killed["fd"] = {"status": "timeout", "time": 60.2, "cpu": None, "length": None}
    table = markdown([row, killed], fd=True).splitlines()
    assert table[2] == "| d | p.pddl | yes | timeout | - | 61.00 / 30.50 | - | solved | 1.50 / 1.25 | 7 |"
    assert table[3] == "| e | p.pddl | yes | solved | yes | 61.00 / 30.50 | 3 | timeout | 60.20 / - | - |"
