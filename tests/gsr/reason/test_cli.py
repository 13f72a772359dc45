"""`gsr solve` and `gsr reason`: output, JSON, exit codes for impossible goals, bad output and bad files."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from gsr.cli import app

from .conftest import SCENE

runner = CliRunner()


def _scene(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(SCENE))
    return str(path)


def test_solve_prints_checked_steps(tmp_path):
    res = runner.invoke(app, ["solve", "x", "--scene", _scene(tmp_path), "--goal", "(in red_cube1 blue_box)"])
    assert res.exit_code == 0, res.output
    assert "1. (pick red_cube1 table) +(holding red_cube1)" in res.output
    assert "solved: goal reached after 2 step(s)" in res.output


def test_solve_json_goal_mode(tmp_path):
    args = [
        "solve",
        "x",
        "--scene",
        _scene(tmp_path),
        "--goal",
        "(in red_cube1 blue_box)",
        "--mode",
        "goal",
        "--json",
    ]
    res = runner.invoke(app, args)
    data = json.loads(res.stdout)
    assert res.exit_code == 0 and data["success"] and data["counts"]["planner_steps"] == 2


def test_solve_exit_codes(tmp_path):
    scene = _scene(tmp_path)
    impossible = runner.invoke(app, ["solve", "x", "--scene", scene, "--goal", "(in red_cube1 red_cube1)"])
    assert impossible.exit_code == 1 and "no valid plan (unsolvable)" in impossible.output
    bad_goal = runner.invoke(app, ["solve", "x", "--scene", scene, "--goal", "(in red_cube blue_box)"])
    assert bad_goal.exit_code == 1 and "unknown object red_cube" in str(bad_goal.exception or bad_goal.output)
    missing = runner.invoke(app, ["solve", "x", "--scene", str(tmp_path / "none.json")])
    assert missing.exit_code == 1
    bad_backend = runner.invoke(app, ["solve", "x", "--scene", scene, "--backend", "gpt"])
    assert bad_backend.exit_code == 1


def test_solve_never_repaired_exits_1(tmp_path, monkeypatch):
    from .test_openai_backend import FakeOpenAI

    with FakeOpenAI(["nonsense"] * 3) as server:
        args = ["solve", "x", "--scene", _scene(tmp_path), "--goal", "(in red_cube1 blue_box)"]
        res = runner.invoke(app, [*args, "--backend", "openai:m", "--base-url", server.url, "--repairs", "2"])
    assert (
        res.exit_code == 1 and "no valid plan (stuck)" in res.output and "cannot parse the step" in res.output
    )


def test_reason_prompt_and_check(tmp_path):
    scene = _scene(tmp_path)
    res = runner.invoke(app, ["reason", "prompt", "put the red cube in the box", "--scene", scene])
    assert res.exit_code == 0 and res.output.endswith("Next step:\n") and "blue_box on table" in res.output
    steps = tmp_path / "reply.txt"
    steps.write_text("(pick red_cube1 table) +(holding red_cube1) -(hand_empty) -(on red_cube1 table)\n")
    assert runner.invoke(app, ["reason", "check", str(steps), "--scene", scene]).exit_code == 0
    steps.write_text("(pick red_cube1 table) +(holding red_cube1)\n")
    res = runner.invoke(app, ["reason", "check", str(steps), "--scene", scene])
    assert res.exit_code == 1 and "missing delete effect" in res.output


def test_solve_libero_file_with_the_embedded_grounder(libero_dir):
    scene = libero_dir / "libero_10" / "KITCHEN_SCENE3_turn_on_the_stove_and_put_the_moka_pot_on_it.bddl"
    res = runner.invoke(app, ["solve", "turn on the stove and put the moka pot on it", "--scene", str(scene)])
    assert res.exit_code == 0, res.output
    assert "goal: (and (turned_on flat_stove_1) (on moka_pot_1 flat_stove_1))  (grounder)" in res.output
    assert "3. (place_on moka_pot_1 flat_stove_1)" in res.output


def test_solve_instruction_the_grounder_cannot_read(tmp_path):
    res = runner.invoke(app, ["solve", "juggle the purple elephants", "--scene", _scene(tmp_path)])
    assert res.exit_code == 1 and "backend_error" in res.output and "elephant" in res.output


def test_solve_instruction_option_and_formats(tmp_path):
    scene = _scene(tmp_path)
    base = ["solve", "--scene", scene, "--instruction", "put the red cube in the blue box"]
    pddl = runner.invoke(app, [*base, "--format", "pddl"])
    assert pddl.exit_code == 0, pddl.output
    assert pddl.stdout.splitlines()[:2] == ["(pick red_cube1 table)", "(place_in red_cube1 blue_box)"]
    bench = runner.invoke(app, [*base, "--format", "gsr-bench"])
    assert bench.exit_code == 0 and bench.stdout.strip() == "move red_cube1 in blue_box"
    both = runner.invoke(app, [*base, "put it somewhere"])
    assert both.exit_code == 1 and "give the instruction once" in both.output
    bad = runner.invoke(app, [*base, "--format", "yaml"])
    assert bad.exit_code == 1


def test_a_six_step_gsr_solve_calls_the_planner_once_and_builds_no_prompt(tmp_path):
    """The acceptance point of issue 15, through the real command: the grounder backend plans once for a
    6-step solve (no step rejected) and no prompt is built for it."""
    from gsr.benchmarks.bench_solve import counting_planner_and_prompts
    from gsr.benchmarks.suites import get_suite

    task = next(
        t for t in get_suite("rlbench").tasks(None, 0) if t.id == "rlbench_put_groceries_in_cupboard_v1"
    )
    scene = tmp_path / "six.json"
    scene.write_text(task.initial.model_dump_json())
    with counting_planner_and_prompts() as calls:
        res = runner.invoke(
            app, ["solve", "--scene", str(scene), "--instruction", task.instruction, "--json"]
        )
    assert res.exit_code == 0, res.output
    out = json.loads(res.output)
    assert out["status"] == "solved" and len(out["steps"]) == 6, out["status"]
    assert calls == {"plan": 1, "prompt": 0}
