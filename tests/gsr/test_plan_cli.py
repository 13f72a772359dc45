"""``gsr plan`` command function: output, atomic --out, exit codes."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.plan.cli import plan_command
from gsr.plan_format import parse_plan

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "pddl"

TOY_DOMAIN = """(define (domain toy) (:requirements :strips)
  (:predicates (at-a) (at-b))
  (:action go :parameters () :precondition (at-a) :effect (and (at-b) (not (at-a)))))"""
TOY_UNSOLVABLE = """(define (problem u) (:domain toy) (:init (at-a)) (:goal (and (at-a) (at-b))))"""


@pytest.fixture
def blocks() -> tuple[Path, Path]:
    if not DATA.is_dir():
        pytest.skip(f"reference data not found at {DATA}")
    return DATA / "blocks" / "domain.pddl", DATA / "blocks" / "probBLOCKS-5-0.pddl"


def test_prints_ipc_plan(blocks: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    code = plan_command(blocks[0], blocks[1], "astar-lmcut", 30.0, None)
    captured = capsys.readouterr()
    assert code == 0
    assert len(parse_plan(captured.out)) == 12
    assert "; cost = 12 (unit cost)" in captured.out
    assert "astar-lmcut: solved" in captured.err


def test_writes_out_file_atomically(blocks: tuple[Path, Path], tmp_path: Path, capsys) -> None:
    out = tmp_path / "plan.txt"
    assert plan_command(blocks[0], blocks[1], "lazy-ff", 30.0, out) == 0
    assert capsys.readouterr().out == ""
    assert len(parse_plan(out.read_text())) > 0
    assert [p.name for p in tmp_path.iterdir()] == ["plan.txt"]


def test_unsolvable_exit_code(tmp_path: Path, capsys) -> None:
    (tmp_path / "d.pddl").write_text(TOY_DOMAIN)
    (tmp_path / "p.pddl").write_text(TOY_UNSOLVABLE)
    assert plan_command(tmp_path / "d.pddl", tmp_path / "p.pddl", "lazy-ff", 10.0, tmp_path / "o") == 2
    assert not (tmp_path / "o").exists()
    assert "unsolvable" in capsys.readouterr().err


def test_timeout_exit_code(capsys) -> None:
    if not DATA.is_dir():
        pytest.skip(f"reference data not found at {DATA}")
    code = plan_command(DATA / "gripper" / "domain.pddl", DATA / "gripper" / "prob10.pddl", "bfs", 0.0, None)
    assert code == 3
    assert "timeout" in capsys.readouterr().err


def test_bad_files_exit_1_with_one_line(tmp_path: Path, capsys) -> None:
    assert plan_command(tmp_path / "nope.pddl", tmp_path / "nope2.pddl", "lazy-ff", 1.0, None) == 1
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1
    (tmp_path / "bad.pddl").write_text("(define (domain x) (:predicates (p)")
    (tmp_path / "p.pddl").write_text(TOY_UNSOLVABLE)
    assert plan_command(tmp_path / "bad.pddl", tmp_path / "p.pddl", "lazy-ff", 1.0, None) == 1
    err = capsys.readouterr().err
    assert "bad.pddl" in err and err.count("\n") == 1
    assert plan_command(None, tmp_path / "p.pddl", "lazy-ff", 1.0, None) == 1
    assert plan_command(tmp_path / "bad.pddl", tmp_path / "p.pddl", "no-such", 1.0, None) == 1
