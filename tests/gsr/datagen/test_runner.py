"""Sharded output: byte-identical across worker counts, resume, atomic files, datasets loading, CLI."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gsr.cli import app
from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.errors import GSRError

ROWS, SHARD = 900, 300


def _tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted((root / "data").rglob("*.jsonl"))}


@pytest.fixture(scope="module")
def one_worker(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("dg") / "w1"
    generate_dataset(RunConfig(out, ROWS, seed=2, shard_size=SHARD), workers=1, progress=False)
    return out


def test_two_workers_write_identical_shards(one_worker, tmp_path) -> None:
    out = tmp_path / "w2"
    manifest = generate_dataset(RunConfig(out, ROWS, seed=2, shard_size=SHARD), workers=2, progress=False)
    assert manifest["rows"] == ROWS and sum(manifest["splits"].values()) == ROWS
    assert _tree(out) == _tree(one_worker)
    assert not list(out.rglob("*.tmp*"))
    card = (out / "README.md").read_text()
    assert "held-out" in card and "validate_plan" in card


def test_resume_after_interruption_gives_the_same_dataset(one_worker, tmp_path) -> None:
    out = tmp_path / "r"
    cfg = RunConfig(out, ROWS, seed=2, shard_size=SHARD)
    partial = generate_dataset(cfg, progress=False, max_shards=1)  # stops after one shard
    assert partial["complete"] is False and not (out / "README.md").exists()
    # a crash mid-shard leaves a temporary file and a split file without its marker: both harmless
    (out / "data" / "train" / ".part-00001.jsonl.tmp123").write_text("garbage")
    (out / "data" / "train" / "part-00002.jsonl").write_text('{"id": "half written"}\n')
    with pytest.raises(GSRError, match="--resume"):
        generate_dataset(cfg, progress=False)
    done = []
    manifest = generate_dataset(cfg, progress=False, resume=True, on_shard=done.append)
    assert sorted(d["shard"] for d in done) == [1, 2]  # shard 0 was not redone
    assert manifest["rows"] == ROWS
    assert _tree(out) == _tree(one_worker)
    with pytest.raises(GSRError, match="different parameters"):
        generate_dataset(RunConfig(out, ROWS + 1, seed=2, shard_size=SHARD), resume=True, progress=False)


def test_datasets_load_json_reads_every_split(one_worker) -> None:
    from datasets import load_dataset

    files = {
        s: str(one_worker / "data" / s / "*.jsonl")
        for s in ("train", "val", "test")
        if list((one_worker / "data" / s).glob("*.jsonl"))
    }
    ds = load_dataset("json", data_files=files, cache_dir=str(one_worker.parent / "hf-cache"))
    manifest = json.loads((one_worker / "manifest.json").read_text())
    for split in files:
        assert ds[split].num_rows == manifest["splits"][split]
    row = ds["train"][0]
    assert set(row) == {"id", "type", "split", "heldout", "task", "horizon", "input", "output"}
    assert json.loads(row["input"])


def test_cli_generates_and_reports_errors(tmp_path) -> None:
    runner = CliRunner()
    out = tmp_path / "cli"
    result = runner.invoke(
        app, ["datagen", "--out", str(out), "--samples", "200", "--shard-size", "100", "--no-progress"]
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary["rows"] == 200 and summary["plans_rejected_by_checker"] == 0
    again = runner.invoke(app, ["datagen", "--out", str(out), "--samples", "200", "--shard-size", "100"])
    assert again.exit_code == 1
    bad = subprocess.run(
        [sys.executable, "-m", "gsr.cli", "datagen", "--out", str(tmp_path / "x"), "--samples", "0"],
        capture_output=True,
        text=True,
    )
    assert (
        bad.returncode == 1
        and "error: --samples must be positive" in bad.stderr
        and "Traceback" not in bad.stderr
    )
    ray = subprocess.run(
        [
            sys.executable,
            "-m",
            "gsr.cli",
            "datagen",
            "--out",
            str(tmp_path / "y"),
            "--samples",
            "10",
            "--backend",
            "spark",
        ],
        capture_output=True,
        text=True,
    )
    assert ray.returncode == 1 and "unknown backend" in ray.stderr


@pytest.mark.slow
def test_killed_run_resumes_without_loss_or_duplicates(tmp_path) -> None:
    """Kill a real `gsr datagen` process mid-run, resume it, compare with an uninterrupted run."""
    args = ["--samples", "6000", "--shard-size", "500", "--seed", "9", "--no-progress"]
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        [sys.executable, "-m", "gsr.cli", "datagen", "--out", str(out), *args], start_new_session=True
    )
    deadline = time.time() + 120
    while time.time() < deadline and len(list((out / ".progress").glob("part-*.json"))) < 3:
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (out / "manifest.json").exists()
    subprocess.run(
        [sys.executable, "-m", "gsr.cli", "datagen", "--out", str(out), *args, "--resume"], check=True
    )
    ref = tmp_path / "ref"
    subprocess.run(
        [sys.executable, "-m", "gsr.cli", "datagen", "--out", str(ref), *args, "--workers", "2"], check=True
    )
    assert _tree(out) == _tree(ref)
    ids = [
        json.loads(line)["id"] for p in (out / "data").rglob("*.jsonl") for line in p.read_text().splitlines()
    ]
    assert len(ids) == len(set(ids)) == 6000


@pytest.mark.slow
def test_ray_backend_writes_the_same_bytes(one_worker, tmp_path) -> None:
    pytest.importorskip("ray")
    out = tmp_path / "ray"
    generate_dataset(RunConfig(out, ROWS, seed=2, shard_size=SHARD), workers=2, backend="ray", progress=False)
    assert _tree(out) == _tree(one_worker)
