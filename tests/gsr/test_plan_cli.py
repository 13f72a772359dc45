"""``gsr plan`` command function: output, atomic --out, exit codes."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.plan.cli import plan_command
from gsr.plan_format import parse_plan
from tests.data_paths import LIBERO
from tests.data_paths import PDDL as DATA

TOY_DOMAIN = """(define (domain toy) (:requirements :strips)
  (:predicates (at-a) (at-b))
  (:action go :parameters () :precondition (at-a) :effect (and (at-b) (not (at-a)))))"""
TOY_UNSOLVABLE = """(define (problem u) (:domain toy) (:init (at-a)) (:goal (and (at-a) (at-b))))"""


@pytest.fixture
def blocks() -> tuple[Path, Path]:
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
    capsys.readouterr()
    (tmp_path / "d.pddl").write_text(TOY_DOMAIN)
    for limit in (-1.0, float("nan")):
        assert plan_command(tmp_path / "d.pddl", tmp_path / "p.pddl", "lazy-ff", limit, None) == 1
        err = capsys.readouterr().err
        assert err.startswith("error: --timeout") and err.count("\n") == 1


BOWL_IN_DRAWER = (
    "libero_10/KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it.bddl"
)


def _libero_problem(bddl: Path):
    from gsr.libero import libero_task
    from gsr.pddl.bddl import load_bddl
    from gsr.resources import load_builtin_domain

    domain = load_builtin_domain("tabletop")
    return domain, libero_task(load_bddl(bddl), domain)[1]


@pytest.mark.parametrize("with_domain", [False, True])
def test_bddl_problem_plans_against_tabletop_domain(with_domain: bool, tmp_path: Path, capsys) -> None:
    from gsr.resources import domain_path
    from gsr.validate import validate_plan

    bddl = LIBERO / BOWL_IN_DRAWER
    if not bddl.is_file():
        pytest.skip(f"reference data not found at {bddl}")
    out = tmp_path / "plan.txt"
    domain = domain_path("tabletop") if with_domain else None
    assert plan_command(domain, bddl, "lazy-ff", 30.0, out) == 0
    found = parse_plan(out.read_text())
    assert [s.action for s in found] == ["pick", "place_in", "close"]
    assert validate_plan(*_libero_problem(bddl), found).valid
    assert "lazy-ff: solved" in capsys.readouterr().err


def test_bad_bddl_is_exit_1(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "broken.bddl"
    bad.write_text("(define (problem x) (:domain robosuite) (:objects a - ")
    assert plan_command(None, bad, "lazy-ff", 5.0, None) == 1
    err = capsys.readouterr().err
    assert err.startswith("error:") and "broken.bddl" in err and err.count("\n") == 1


def test_planner_fd_delegates_to_fast_downward(blocks: tuple[Path, Path], capsys) -> None:
    from gsr.plan.fast_downward import find_fast_downward

    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    assert plan_command(blocks[0], blocks[1], "fd", 60.0, None) == 0
    captured = capsys.readouterr()
    assert len(parse_plan(captured.out)) >= 12
    assert "fd: solved" in captured.err


def test_gsr_plan_typer_exit_codes(blocks: tuple[Path, Path], tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from gsr.cli import app

    runner = CliRunner()
    solved = runner.invoke(app, ["plan", str(blocks[0]), str(blocks[1]), "--planner", "astar-lmcut"])
    assert solved.exit_code == 0, solved.output
    assert "(unstack" in solved.output or "(pick-up" in solved.output
    (tmp_path / "d.pddl").write_text(TOY_DOMAIN)
    (tmp_path / "p.pddl").write_text(TOY_UNSOLVABLE)
    assert runner.invoke(app, ["plan", str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl")]).exit_code == 2
    gripper = DATA / "gripper"
    args = [
        "plan",
        str(gripper / "domain.pddl"),
        str(gripper / "prob10.pddl"),
        "--planner",
        "bfs",
        "--timeout",
        "0",
    ]
    assert runner.invoke(app, args).exit_code == 3
    assert runner.invoke(app, ["plan", str(tmp_path / "missing.pddl")]).exit_code == 1


def test_planner_fd_with_action_costs_reports_the_plan_cost(capsys) -> None:
    """FD prints no unit-cost count under a metric: the cost comes from validating its plan."""
    from gsr.plan.fast_downward import find_fast_downward

    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    problem = DATA / "tetris" / "p04-10.pddl"
    code = plan_command(None, problem, "fd", 300.0, None)  # DOMAIN found beside the problem
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "Traceback" not in captured.err
    cost = float(captured.err.rsplit("cost ", 1)[1].split()[0])
    assert cost >= len(parse_plan(captured.out)) > 0  # tetris moves cost 1-3 each


def test_problem_alone_finds_its_domain_file(tmp_path: Path, capsys) -> None:
    from gsr.pddl.files import find_domain_file

    (tmp_path / "p01.pddl").write_text(TOY_UNSOLVABLE.replace("(and (at-a) (at-b))", "(at-b)"))
    assert find_domain_file(tmp_path / "p01.pddl") is None
    assert plan_command(None, tmp_path / "p01.pddl", "lazy-ff", 5.0, None) == 1
    assert "no domain file" in capsys.readouterr().err
    (tmp_path / "domain_p01.pddl").write_text(TOY_DOMAIN)  # FD collection style (psr-small etc.)
    assert find_domain_file(tmp_path / "p01.pddl") == tmp_path / "domain_p01.pddl"
    (tmp_path / "p01-domain.pddl").write_text(TOY_DOMAIN)  # tried before domain_NAME
    assert find_domain_file(tmp_path / "p01.pddl") == tmp_path / "p01-domain.pddl"
    assert plan_command(None, tmp_path / "p01.pddl", "lazy-ff", 5.0, None) == 0
    assert "(go)" in capsys.readouterr().out


def test_an_unexpected_planner_failure_is_one_line(blocks: tuple[Path, Path], monkeypatch, capsys) -> None:
    import gsr.plan.cli

    def broken(*args, **kwargs):
        raise TypeError("unsupported format string passed to NoneType.__format__")

    monkeypatch.setattr(gsr.plan.cli, "plan", broken)  # the command's own binding of gsr.plan.api.plan
    assert plan_command(blocks[0], blocks[1], "lazy-ff", 5.0, None) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: internal planner error (TypeError") and err.count("\n") == 1


def test_gsr_validate_on_a_deeply_nested_problem_is_one_line(
    blocks: tuple[Path, Path], tmp_path: Path
) -> None:
    import subprocess
    import sys

    deep = "(not " * 3000 + "(clear a)" + ")" * 3000
    problem = tmp_path / "deep.pddl"
    problem.write_text(f"(define (problem p) (:domain blocks) (:objects a) (:init) (:goal {deep}))")
    plan = tmp_path / "plan.txt"
    plan.write_text("(pick-up a)\n")
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "from gsr.cli import main; main()",
            "validate",
            str(blocks[0]),
            str(problem),
            str(plan),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1
    assert done.stderr.startswith("error:") and done.stderr.count("\n") == 1, done.stderr
    assert "Traceback" not in done.stderr


def test_gsr_validate_finds_the_domain_beside_the_problem(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from gsr.cli import app

    runner = CliRunner()
    problem = tmp_path / "p01.pddl"
    problem.write_text(TOY_UNSOLVABLE.replace("(and (at-a) (at-b))", "(at-b)"))
    plan = tmp_path / "plan.txt"
    plan.write_text("(go)\n")
    lonely = runner.invoke(app, ["validate", str(problem), str(plan)])  # gsr.cli.main prints GSRError
    assert lonely.exit_code == 1 and "needs its DOMAIN file (none beside it" in str(lonely.exception)
    (tmp_path / "domain.pddl").write_text(TOY_DOMAIN)
    found = runner.invoke(app, ["validate", str(problem), str(plan)])
    assert found.exit_code == 0, found.output
    # DOMAIN PROBLEM without the plan: the domain file is taken for the problem; say so in one line
    swapped = runner.invoke(app, ["validate", str(tmp_path / "domain.pddl"), str(problem)])
    assert swapped.exit_code == 1 and "this is a domain file; give DOMAIN PROBLEM" in str(swapped.exception)
