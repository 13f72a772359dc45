"""Fine-tuning: examples in the reasoner's format, a tiny run that loads as a transformers backend, LoRA."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.errors import GSRError
from gsr.reason.step_format import parse_first_step
from gsr.resources import load_builtin_domain
from gsr.train.format import read_rows, row_example
from gsr.train.tiny import TinySpec

pytest.importorskip("transformers")
pytest.importorskip("peft")

MICRO = TinySpec(vocab_size=400, hidden=32, layers=1, heads=2, intermediate=64, context=512)


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("train") / "ds"
    manifest = generate_dataset(RunConfig(out, 2500, seed=2, shard_size=2500), progress=False)
    assert manifest["splits"].get("val", 0) > 0  # seed 2 gives val scenes: the run reports a val loss
    return out


def test_examples_use_the_reasoner_prompt_and_step_language(data) -> None:
    from gsr.reason.prompt import DONE

    domain = load_builtin_domain()
    files = sorted(str(p) for p in (data / "data" / "train").glob("*.jsonl"))
    seen = set()
    for row in read_rows(files, ("next_action", "goal_interpretation", "forward_prediction"), 200):
        ex = row_example(row, domain)
        seen.add(ex.type)
        if ex.type == "next_action":
            assert ex.prompt.rstrip().endswith("Next step:") and "Scene:\n" in ex.prompt
            if ex.answer != DONE:
                step = parse_first_step(ex.answer)
                assert step.claims_effects  # the answer states the complete change
        elif ex.type == "goal_interpretation":
            assert ex.prompt.rstrip().endswith("Goal:") and ex.answer.startswith("(and ")
    assert seen == {"next_action", "goal_interpretation", "forward_prediction"}


def _cfg(data: Path, out: Path, **kw):
    from gsr.train.sft import TrainConfig

    return TrainConfig(
        data,
        kw.pop("model", "tiny"),
        out,
        max_steps=2,
        batch_size=2,
        train_rows=40,
        eval_rows=8,
        tiny=MICRO,
        **kw,
    )


def test_tiny_run_writes_a_folder_the_transformers_backend_loads(data, tmp_path) -> None:
    from transformers import AutoModelForCausalLM, AutoTokenizer

    from gsr.reason.hf_backend import TransformersBackend
    from gsr.reason.prompt import build_prompt
    from gsr.train.sft import train

    out = tmp_path / "tiny"
    metrics = train(_cfg(data, out), log=lambda _: None)
    assert metrics["train_loss"] > 0 and "val_loss" in metrics
    assert AutoModelForCausalLM.from_pretrained(out).config.model_type == "llama"
    assert AutoTokenizer.from_pretrained(out).eos_token == "<|endoftext|>"
    info = json.loads((out / "gsr_training.json").read_text())
    assert info["train_examples"] > 0 and info["metrics"]["steps"] == 2
    assert not list(tmp_path.glob(".tiny*"))  # no temporary folders left
    backend = TransformersBackend(str(out), device="cpu", max_new_tokens=8)
    from gsr.datagen.schema import decode

    row = next(read_rows([str(p) for p in (data / "data" / "train").glob("*.jsonl")], ("next_action",), 1))
    _, inp, _ = decode(row)
    reply = backend.complete(build_prompt(inp.graph, load_builtin_domain(), inp.instruction))
    assert isinstance(reply, str)
    with pytest.raises(GSRError, match="not empty"):
        train(_cfg(data, out), log=lambda _: None)
    # the no-checker baseline agent runs the same checkpoint open loop, constrained or not
    from gsr.datagen.tasks import generated_tasks
    from gsr.episode import Agent
    from gsr.train.openloop import OpenLoopAgent

    task = generated_tasks(data, "train", limit=1)[0]
    for constrained in (False, True):
        agent = OpenLoopAgent(backend=f"transformers:{out}", constrained=constrained)
        assert isinstance(agent, Agent)  # the core's episode seam, checked at runtime
        agent.reset(task, load_builtin_domain(), 0)
        step = agent.act(task.initial, task.instruction)
        assert step is None or step.add is None  # claimed effects never reach the executor
    if constrained and step is not None:
        from gsr.facts import state_from_graph
        from gsr.semantics import applicable

        domain = load_builtin_domain()
        assert applicable(domain, state_from_graph(task.initial, domain), step.action, step.args)


def test_lora_on_a_checkpoint_merges_into_a_plain_model(data, tmp_path) -> None:
    from transformers import AutoModelForCausalLM

    from gsr.train.sft import train

    base = tmp_path / "base"
    train(_cfg(data, base), log=lambda _: None)
    out = tmp_path / "lora"
    train(_cfg(data, out, model=str(base), lora=True), log=lambda _: None)
    model = AutoModelForCausalLM.from_pretrained(out)
    assert not any("lora" in name for name, _ in model.named_parameters())


def test_bad_options_are_clear_errors(data, tmp_path) -> None:
    from typer.testing import CliRunner

    from gsr.cli import app

    runner = CliRunner()
    r = runner.invoke(
        app, ["train", "--data", str(tmp_path), "--model", "tiny", "--out", str(tmp_path / "o")]
    )
    assert r.exit_code == 1 and "no data/train folder" in str(r.exception or r.output)
    r = runner.invoke(
        app,
        ["train", "--data", str(data), "--model", "tiny", "--out", str(tmp_path / "o"), "--types", "poetry"],
    )
    assert r.exit_code == 1
    from gsr.train.sft import train

    with pytest.raises(GSRError, match="not 'tiny' or 'small' and not a local checkpoint"):
        train(_cfg(data, tmp_path / "x", model=str(tmp_path / "missing")), log=lambda _: None)


def test_time_budget_stops_training_early_and_still_saves(data, tmp_path) -> None:
    from gsr.train.sft import train

    out = tmp_path / "budget"
    cfg = _cfg(data, out, time_budget=1e-6)
    cfg.max_steps = 50
    metrics = train(cfg, log=lambda _: None)
    assert metrics["steps"] == 1  # the budget is checked after each optimizer step
    assert (out / "config.json").is_file()
    assert json.loads((out / "gsr_training.json").read_text())["config"]["time_budget"] == 1e-6


def test_scratch_presets_and_bad_time_budget(data, tmp_path) -> None:
    from typer.testing import CliRunner

    from gsr.cli import app
    from gsr.train.sft import TrainConfig
    from gsr.train.tiny import SCRATCH_SPECS

    small = TrainConfig(Path("d"), "small", Path("o"))
    assert small.scratch and small.spec == SCRATCH_SPECS["small"] and small.spec.context == 2048
    assert not TrainConfig(Path("d"), "/no/such/checkpoint", Path("o")).scratch
    args = [
        "train",
        "--data",
        str(data),
        "--model",
        "tiny",
        "--out",
        str(tmp_path / "o"),
        "--time-budget",
        "0",
    ]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 1 and "--time-budget must be positive" in str(r.exception or r.output)
    assert not (tmp_path / "o").exists()
