"""Compact-format training: planner-labelled rows, recovery rows, a tiny model that learns to choose steps."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from gsr.check import check_step
from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.errors import GSRError
from gsr.facts import state_from_graph
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


def test_a_step_budget_gives_the_same_training_whatever_the_cpu_time(domain, samples) -> None:
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

        report, _ = fit(model, rows, domain, tok.get_vocab(), 5, 0, 4, 3e-3, None, schedule, log, 12)
        assert report.steps == 12
        losses.append(report.last_loss)
    assert losses[0] == losses[1]
