"""Compact-format training: planner-labelled rows, recovery rows, a tiny model that learns to choose steps."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from gsr.check import check_step
from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.pddl.parser import parse_formula
from gsr.resources import load_builtin_domain

pytest.importorskip("transformers")


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("compact") / "ds"
    generate_dataset(RunConfig(out, 3000, seed=5, shard_size=3000), progress=False)
    return out


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def samples(data):
    from gsr.train.compact import dataset_samples

    return dataset_samples(data, "train")


def test_dataset_and_recovery_rows_carry_applicable_planner_steps(samples, domain) -> None:
    from gsr.train.compact import recovery_samples

    assert len(samples) > 200 and any(s.answer is None for s in samples) and any(s.history for s in samples)
    recovery = recovery_samples(samples, 12, 0, domain)
    assert len(recovery) >= 8
    for s in [*random.Random(0).sample(samples, 20), *recovery]:
        if s.answer is not None:
            assert check_step(domain, state_from_graph(s.graph, domain), s.answer).ok
    # each recovery row starts off the plan: its history ends with the random detour
    assert all(s.source == "recovery" and s.history for s in recovery)


def test_a_tiny_model_fits_its_rows_and_constrained_decoding_stays_applicable(samples, domain) -> None:
    """Training, encoding and the ranking decoder agree: a tiny model that fits 24 rows (inference
    naming) picks their planner step far more often than a uniform pick among the applicable steps."""
    import torch

    from gsr.reason.applicable import applicable_steps
    from gsr.reason.backend import Query
    from gsr.reason.compact import build_tokenizer
    from gsr.reason.compact_decode import CompactAnswerer, answer_key
    from gsr.reason.prompt import Prompt
    from gsr.reason.step_format import format_step
    from gsr.train.compact import CompactSpec, fit, new_model

    torch.set_num_threads(1)
    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=64, layers=2, heads=2, intermediate=128, context=256), 0)
    rows = random.Random(1).sample([s for s in samples if s.answer is not None], 24)
    report, _ = fit(
        model,
        rows,
        domain,
        tok.get_vocab(),
        600,
        0,
        8,
        3e-3,
        log=lambda _: None,
        max_steps=150,
        shuffle_names=False,
    )
    assert report.steps == 150
    answerer = CompactAnswerer(model, tok)
    hits, chance = 0, 0.0
    for s in rows:
        allowed = tuple(format_step(a) for a in applicable_steps(domain, s.graph))
        reply = answerer.answer(
            Query("step", Prompt("", ""), s.graph, domain, "", s.goal, s.history, allowed)
        )
        assert reply in allowed  # constrained decoding only ever emits an applicable step
        hits += answer_key(reply) == (s.answer.action, s.answer.args)
        chance += 1 / len(allowed)
    assert hits >= 18 and hits > 3 * chance, (hits, chance)


def test_save_is_atomic_and_refuses_a_non_empty_folder(tmp_path, domain) -> None:
    from gsr.reason.compact import MARKER, build_tokenizer
    from gsr.train.compact import CompactSpec, new_model, save

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=128), 0)
    out = tmp_path / "m"
    save(model, tok, out, {"x": 1})
    assert (out / MARKER).is_file() and (out / "gsr_training.json").is_file()
    assert not list(tmp_path.glob(".m*"))
    with pytest.raises(GSRError, match="not empty"):
        save(model, tok, out, {})


def test_bench_training_recipe_needs_an_output_folder(capsys) -> None:
    from gsr.benchmarks.bench_training import main

    with pytest.raises(SystemExit):
        main(["--recipe", "cpu"])
    assert "--out" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--workers", "1"])
    assert "--recipe" in capsys.readouterr().err


@pytest.mark.parametrize("group", [1, 3])
def test_a_step_budget_gives_the_same_training_whatever_the_cpu_time(domain, samples, group) -> None:
    # with max_steps the learning-rate schedule reads the share of steps done: two runs of one seed are
    # equal even when one process is slowed down (the CPU seconds are only a cap)
    import time as _time

    import torch

    from gsr.reason.compact import build_tokenizer
    from gsr.train.compact import CompactSpec, cosine, fit, new_model

    torch.set_num_threads(1)
    tok = build_tokenizer(domain)
    rows = [s for s in samples if s.answer is not None][:16]
    losses = []
    for slow in (False, True):
        model = new_model(tok, CompactSpec(hidden=32, layers=1, heads=2, intermediate=64, context=256), 0)

        def log(_: str, slow: bool = slow) -> None:
            pass

        def schedule(p: float, slow: bool = slow) -> float:
            if slow:  # burn CPU time between steps, as a loaded machine would
                end = _time.process_time() + 0.01
                while _time.process_time() < end:
                    pass
            return cosine()(p)

        report, _ = fit(
            model, rows, domain, tok.get_vocab(), 5, 0, 4, 3e-3, None, schedule, log, 12, group=group
        )
        assert report.steps == 12
        losses.append(report.last_loss)
    assert losses[0] == losses[1]


def test_fit_keeps_the_weights_of_the_best_selection_score(domain, samples) -> None:
    """Selection scores the model every few steps and keeps the best weights (the later on a tie)."""
    import torch

    from gsr.reason.compact import build_tokenizer
    from gsr.train.compact import CompactSpec, fit, new_model

    torch.set_num_threads(1)
    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=32, layers=1, heads=2, intermediate=64, context=256), 0)
    snapshots: list[dict] = []
    peak = [0.1, 0.9, 0.5, 0.9, 0.2]  # the 2nd and 4th evaluations tie: the 4th (step 8) is kept

    def select(m) -> float:
        snapshots.append({k: v.clone() for k, v in m.state_dict().items()})
        return peak[len(snapshots) - 1]

    rows = [s for s in samples if s.answer is not None][:40]
    report, _ = fit(
        model,
        rows,
        domain,
        tok.get_vocab(),
        60,
        0,
        4,
        3e-3,
        log=lambda _: None,
        max_steps=10,
        group=2,
        select=select,
        select_every=2,
    )
    assert [s for s, _ in report.selection] == [2, 4, 6, 8, 10] and report.selected_step == 8
    kept = model.state_dict()
    assert all(torch.equal(kept[k], snapshots[3][k]) for k in kept)
    assert not all(torch.equal(kept[k], snapshots[4][k]) for k in kept)


def test_ranking_metric_and_admissible_steps(domain, samples) -> None:
    """ranking_accuracy counts a row when the planner's step is the best-scored applicable line (what
    constrained decoding picks); admissible() drops a step whose next state the episode already saw."""
    from collections import Counter

    import torch

    from gsr.reason.applicable import applicable_steps
    from gsr.reason.backend import Query
    from gsr.reason.compact import build_tokenizer
    from gsr.reason.compact_decode import CompactAnswerer, answer_key
    from gsr.reason.prompt import Prompt
    from gsr.reason.step_format import format_step
    from gsr.train.compact import CompactSpec, admissible, fit, new_model, ranking_accuracy

    torch.set_num_threads(1)
    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=48, layers=2, heads=2, intermediate=96, context=256), 0)
    rows = random.Random(3).sample([s for s in samples if s.answer is not None], 16)
    before = ranking_accuracy(model, rows, domain, tok)
    fit(
        model,
        rows,
        domain,
        tok.get_vocab(),
        600,
        0,
        8,
        3e-3,
        log=lambda _: None,
        max_steps=120,
        shuffle_names=False,
    )
    after = ranking_accuracy(model, rows, domain, tok)
    answerer = CompactAnswerer(model, tok)
    hits = 0
    for s in rows:
        lines = tuple(format_step(a) for a in applicable_steps(domain, s.graph))
        reply = answerer.answer(Query("step", Prompt("", ""), s.graph, domain, "", s.goal, s.history, lines))
        hits += answer_key(reply) == (s.answer.action, s.answer.args)
    assert after == hits / len(rows)
    assert after >= 0.75 and after > before + 0.3, (before, after)
    # a done row is not counted: ranking is about steps
    done = [s for s in samples if s.answer is None][:3]
    assert ranking_accuracy(model, [*rows, *done], domain, tok) == after

    s = rows[0]
    steps, nexts, lines = admissible(domain, s.graph, Counter())
    assert lines == tuple(format_step(a) for a in steps) and len(steps) > 1
    seen = Counter([nexts[0].atoms])
    _, _, fewer = admissible(domain, s.graph, seen)
    assert format_step(steps[0]) not in fewer and len(fewer) == len(lines) - 1


def test_evaluate_refuses_a_folder_that_is_not_a_compact_model(tmp_path, data, capsys) -> None:
    from gsr.train.evaluate import main

    (tmp_path / "m").mkdir()
    assert main(["--data", str(data), str(tmp_path / "m")]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "not a compact-format model" in err and "\n" not in err


def test_long_validation_tasks_join_two_goals_of_a_scene_into_a_longer_plan(data, domain, tmp_path) -> None:
    from gsr.datagen.tasks import generated_tasks
    from gsr.plan import api as plan_api
    from gsr.task_spec import load_task
    from gsr.train.longval import main

    assert main(["--data", str(data), "--out", str(tmp_path / "lv"), "--count", "2", "--min-plan", "5"]) == 0
    files = sorted((tmp_path / "lv").glob("*.json"))
    assert len(files) == 2
    val_goals = {t.id: t.goal for t in generated_tasks(data, "val")}
    for path in files:
        task = load_task(path)
        first, second = task.metadata["from"]
        goal = parse_formula(task.goal)
        assert len(goal.parts) > max(len(parse_formula(val_goals[x]).parts) for x in (first, second))
        found = plan_api.plan_graph(domain, task.initial, goal, timeout=10.0)
        assert found.solved and len(found.plan.steps) == task.metadata["plan"] >= 5


def test_evaluate_runs_long_tasks_with_the_markers_or_the_given_goal_order(
    data, domain, tmp_path, capsys
) -> None:
    import json

    from gsr.datagen.tasks import generated_tasks
    from gsr.reason.compact import build_tokenizer
    from gsr.task_spec import task_json
    from gsr.train.compact import CompactSpec, new_model, save
    from gsr.train.evaluate import main

    tok = build_tokenizer(domain)
    model = new_model(tok, CompactSpec(hidden=16, layers=1, heads=2, intermediate=32, context=256), 0)
    save(model, tok, tmp_path / "m", {}, 3, goal_window=1, goal_order="dependencies")
    (tmp_path / "lv").mkdir()
    for t in generated_tasks(data, "val")[:2]:
        (tmp_path / "lv" / f"{t.id}.json").write_text(task_json(t))
    args = ["--data", str(data), "--rows", "4", "--tasks", "1", "--long-tasks", str(tmp_path / "lv")]
    assert main([*args, str(tmp_path / "m")]) == 0
    line = json.loads(capsys.readouterr().out)
    assert line["long_tasks_constrained"].endswith("/2") and line["val_tasks_constrained"].endswith("/1")
    assert (line["goal_window"], line["goal_order"]) == (1, "dependencies")
    assert main([*args, "--goal-order", "goal", "--goal-window", "2", str(tmp_path / "m")]) == 0
    line = json.loads(capsys.readouterr().out)
    assert (line["goal_window"], line["goal_order"]) == (2, "goal")
    assert main([*args[:-2], "--long-tasks", str(tmp_path / "none"), str(tmp_path / "m")]) == 1
    assert "no task files" in capsys.readouterr().err


class _ScriptedAnswerer:
    """Answers every step query with the ``pick``-th admissible line (None: a line that names no step)."""

    version = 1

    def __init__(self, pick: int | None) -> None:
        self.pick = pick
        self.queries = 0

    def answer(self, query) -> str:
        self.queries += 1
        return "(no_such_step a b)" if self.pick is None else query.allowed[self.pick]


def test_constrained_episode_records_graphs_steps_and_why_it_stopped(samples, domain) -> None:
    from gsr.semantics import goal_holds
    from gsr.train.compact import constrained_episode

    s = next(s for s in samples if s.answer is not None and not s.history)
    run = constrained_episode(_ScriptedAnswerer(0), domain, s.graph, s.goal, max_steps=2)
    assert len(run.graphs) == len(run.steps) + 1 and run.graphs[0] is s.graph
    if run.end == "solved":
        assert goal_holds(domain, s.goal, state_from_graph(run.graphs[-1], domain))
    else:
        assert run.end == "max_steps" and len(run.steps) == 2
    for before, step, after in zip(run.graphs[:-1], run.steps, run.graphs[1:], strict=True):
        assert check_step(domain, state_from_graph(before, domain), step).ok
        assert state_from_graph(after, domain).atoms != state_from_graph(before, domain).atoms

    silent = _ScriptedAnswerer(None)
    run = constrained_episode(silent, domain, s.graph, s.goal, max_steps=5)
    assert (run.end, run.steps, len(run.graphs), silent.queries) == ("no_pick", [], 1, 1)

    done = constrained_episode(_ScriptedAnswerer(0), domain, s.graph, parse_formula("(and)"), max_steps=5)
    assert (done.end, done.steps) == ("solved", [])
