"""``gsr datagen``: the command behind the thin typer function in gsr/cli.py."""

from __future__ import annotations

import json
from pathlib import Path

from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.errors import GSRError


def datagen_command(
    out: Path,
    samples: int,
    workers: int,
    backend: str,
    seed: int,
    resume: bool,
    shard_size: int,
    progress: bool,
) -> int:
    """Generate (or resume) a dataset; prints a one-line summary; exit code 0."""
    if out.exists() and not out.is_dir():
        raise GSRError(f"{out}: not a directory")
    cfg = RunConfig(out, samples, seed, shard_size)
    manifest = generate_dataset(cfg, workers=workers, backend=backend, resume=resume, progress=progress)
    if not manifest.get("complete", True):
        raise GSRError("generation stopped before all shards were written; rerun with --resume")
    run = manifest["last_run"]
    rate = manifest["rows"] / run["seconds"] if run["seconds"] and run["shards"] == cfg.n_shards else None
    summary = {
        "out": str(out),
        "rows": manifest["rows"],
        "splits": manifest["splits"],
        "seconds": run["seconds"],
        "rows_per_second": round(rate, 1) if rate else None,
        "plans_validated": manifest["generator"].get("plans_validated", 0),
        "plans_rejected_by_checker": manifest["generator"].get("plans_rejected_by_checker", 0),
    }
    print(json.dumps(summary))
    return 0
