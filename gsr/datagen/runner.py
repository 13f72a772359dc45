"""Run the generator: shards in parallel (local processes or Ray), atomic files, resume, manifest, card.

Layout of an output directory::

    DIR/README.md                      dataset card (written last)
    DIR/manifest.json                  counts, parameters, checker statistics
    DIR/data/{train,val,test}/part-NNNNN.jsonl
    DIR/.progress/run.json             the run's parameters (resume refuses a different run)
    DIR/.progress/part-NNNNN.json      written after a shard's files: the shard is complete

A shard's files are written to temporary names and renamed; its progress marker is renamed into
place last, so an interrupted run leaves either a complete shard or one that ``--resume`` redoes.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gsr.datagen.card import dataset_card
from gsr.datagen.generate import generate_shard
from gsr.datagen.schema import SCHEMA_VERSION, SPLITS
from gsr.errors import GSRError
from gsr.io import write_bytes_atomic

DEFAULT_SHARD_SIZE = 5000
GENERATOR_VERSION = 1


@dataclass(frozen=True)
class RunConfig:
    """What determines the dataset's bytes: seed, size and shard size (not the worker count)."""

    out: Path
    samples: int
    seed: int = 0
    shard_size: int = DEFAULT_SHARD_SIZE

    @property
    def n_shards(self) -> int:
        """Number of shards."""
        return math.ceil(self.samples / self.shard_size)

    def shard_rows(self, shard: int) -> int:
        """Rows in shard ``shard`` (the last one holds the remainder)."""
        return min(self.shard_size, self.samples - shard * self.shard_size)

    def params(self) -> dict[str, Any]:
        """The parameters recorded in ``run.json``."""
        return {
            "samples": self.samples,
            "seed": self.seed,
            "shard_size": self.shard_size,
            "generator_version": GENERATOR_VERSION,
            "schema_version": SCHEMA_VERSION,
        }


def _marker(out: Path, shard: int) -> Path:
    return out / ".progress" / f"part-{shard:05d}.json"


def shard_done(out: Path, shard: int) -> bool:
    """True when the shard's marker exists and its files match the recorded sizes."""
    marker = _marker(out, shard)
    if not marker.is_file():
        return False
    try:
        info = json.loads(marker.read_text())
    except (OSError, json.JSONDecodeError):
        return False
    for split, meta in info.get("files", {}).items():
        path = out / "data" / split / f"part-{shard:05d}.jsonl"
        if not path.is_file() or path.stat().st_size != meta["bytes"]:
            return False
    return True


def run_shard(out: str, seed: int, shard: int, size: int) -> dict[str, Any]:
    """Generate one shard and write it atomically; returns its marker (picklable: used by workers)."""
    start = time.perf_counter()
    result = generate_shard(seed, shard, size)
    root = Path(out)
    files: dict[str, Any] = {}
    for split in SPLITS:
        rows = result.rows[split]
        path = root / "data" / split / f"part-{shard:05d}.jsonl"
        if not rows:
            path.unlink(missing_ok=True)  # a stale file from another run must not be read
            continue
        data = "".join(json.dumps(r, separators=(",", ":"), ensure_ascii=False) + "\n" for r in rows).encode()
        write_bytes_atomic(path, data, fsync=True)
        files[split] = {"rows": len(rows), "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    info = {
        "shard": shard,
        "rows": size,
        "files": files,
        "stats": dict(result.stats),
        "seconds": time.perf_counter() - start,
    }
    write_bytes_atomic(_marker(root, shard), json.dumps(info, indent=1).encode())
    return info


def _local(cfg: RunConfig, todo: list[int], workers: int) -> Iterator[dict[str, Any]]:
    args = [(str(cfg.out), cfg.seed, s, cfg.shard_rows(s)) for s in todo]
    if workers <= 1:
        for a in args:
            yield run_shard(*a)
        return
    import multiprocessing as mp

    ctx = mp.get_context("fork" if sys.platform.startswith("linux") else "spawn")
    with ctx.Pool(workers) as pool:
        yield from pool.imap_unordered(_star, args)


def _star(a: tuple) -> dict[str, Any]:
    return run_shard(*a)


def _ray(cfg: RunConfig, todo: list[int], workers: int) -> Iterator[dict[str, Any]]:
    try:
        import ray
    except ImportError:
        raise GSRError("--backend ray needs Ray: pip install 'gsr[dist]'") from None
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    try:
        remote = ray.remote(num_cpus=1)(run_shard)
        pending = [remote.remote(str(cfg.out), cfg.seed, s, cfg.shard_rows(s)) for s in todo]
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            yield ray.get(done[0])
    finally:
        if started:
            ray.shutdown()


def prepare(cfg: RunConfig, resume: bool) -> list[int]:
    """Check/record the run parameters; the shards still to generate."""
    if cfg.samples <= 0:
        raise GSRError(f"--samples must be positive, got {cfg.samples}")
    if cfg.shard_size <= 0:
        raise GSRError(f"--shard-size must be positive, got {cfg.shard_size}")
    run_file = cfg.out / ".progress" / "run.json"
    if run_file.is_file():
        try:
            old = json.loads(run_file.read_text())
        except json.JSONDecodeError:
            raise GSRError(f"{run_file}: corrupt run record; use a new --out") from None
        if not resume:
            raise GSRError(f"{cfg.out} already holds a generated dataset; pass --resume or use a new --out")
        if old != cfg.params():
            diff = {k: (old.get(k), v) for k, v in cfg.params().items() if old.get(k) != v}
            raise GSRError(f"{cfg.out}: --resume with different parameters {diff}; use the original ones")
    elif not resume and cfg.out.exists() and any(p for p in cfg.out.iterdir() if not p.name.startswith(".")):
        raise GSRError(f"{cfg.out} exists and is not empty; choose a new --out")
    for split in SPLITS:
        (cfg.out / "data" / split).mkdir(parents=True, exist_ok=True)
    (cfg.out / ".progress").mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(run_file, json.dumps(cfg.params(), indent=1).encode())
    return [s for s in range(cfg.n_shards) if not shard_done(cfg.out, s)]


def generate_dataset(
    cfg: RunConfig,
    workers: int = 1,
    backend: str = "local",
    resume: bool = False,
    progress: bool = True,
    max_shards: int | None = None,
    on_shard: Callable[[dict[str, Any]], None] | None = None,
) -> dict[str, Any]:
    """Generate (or finish) the dataset in ``cfg.out``; returns the manifest (None-free JSON)."""
    if backend not in ("local", "ray"):
        raise GSRError(f"unknown backend {backend!r}; choose local or ray")
    if workers < 1:
        raise GSRError(f"--workers must be at least 1, got {workers}")
    todo = prepare(cfg, resume)
    if max_shards is not None:  # stop early (tests and benchmarks simulate an interrupted run)
        todo = todo[:max_shards]
    start = time.perf_counter()
    bar = None
    if progress:
        from tqdm import tqdm

        done_rows = sum(cfg.shard_rows(s) for s in range(cfg.n_shards) if s not in set(todo))
        bar = tqdm(total=cfg.samples, initial=done_rows, unit="rows", desc="datagen", file=sys.stderr)
    runner = _ray if backend == "ray" else _local
    for info in runner(cfg, todo, workers):
        if bar is not None:
            bar.update(info["rows"])
        if on_shard is not None:
            on_shard(info)
    if bar is not None:
        bar.close()
    elapsed = time.perf_counter() - start
    complete = all(shard_done(cfg.out, s) for s in range(cfg.n_shards))
    if not complete:
        return {"complete": False, "seconds": elapsed}
    manifest = build_manifest(cfg)
    manifest["last_run"] = {
        "seconds": round(elapsed, 2),
        "workers": workers,
        "backend": backend,
        "shards": len(todo),
    }
    write_bytes_atomic(cfg.out / "manifest.json", json.dumps(manifest, indent=1).encode())

    write_bytes_atomic(cfg.out / "README.md", dataset_card(manifest).encode())
    return manifest


def build_manifest(cfg: RunConfig) -> dict[str, Any]:
    """Counts by split, type and held-out tag plus generator statistics, from the shard markers and files."""
    stats: Counter = Counter()
    splits: Counter = Counter()
    by_type: dict[str, Counter] = {s: Counter() for s in SPLITS}
    heldout: Counter = Counter()
    files: dict[str, list[str]] = {s: [] for s in SPLITS}
    for shard in range(cfg.n_shards):
        info = json.loads(_marker(cfg.out, shard).read_text())
        stats.update(info["stats"])
        for split, meta in info["files"].items():
            splits[split] += meta["rows"]
            files[split].append(f"data/{split}/part-{shard:05d}.jsonl")
            with open(cfg.out / "data" / split / f"part-{shard:05d}.jsonl", "rb") as fh:
                for line in fh:
                    # the type and heldout fields sit near the start of every row: avoid full JSON parses
                    head = line[:120].decode("utf-8", "replace")
                    by_type[split][head.split('"type":"', 1)[1].split('"', 1)[0]] += 1
                    if split == "test":
                        heldout[head.split('"heldout":"', 1)[1].split('"', 1)[0]] += 1
    return {
        "name": "gsr-manip-cognition",
        "params": cfg.params(),
        "rows": cfg.samples,
        "splits": dict(splits),
        "types": {s: dict(c) for s, c in by_type.items()},
        "test_heldout": dict(heldout),
        "generator": dict(stats),
        "files": files,
    }
