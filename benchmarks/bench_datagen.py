"""Dataset generation throughput: rows/s for a fixed row count, and the extrapolation to 1.6M rows.

    .venv/bin/python benchmarks/bench_datagen.py --samples 50000 --workers 2 [--out DIR] [--json FILE]

Reports wall-clock rows/s and rows per CPU-second of the worker processes (user + system time), plus
the load average: on a shared machine wall time depends on what else runs, CPU time much less.
``dedicated_2core_rows_per_s`` = 2 x rows per CPU-second is what two otherwise idle cores would give;
the 1.6M-row estimates divide 1.6M by each rate.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

from gsr.datagen.runner import RunConfig, generate_dataset

TARGET_ROWS = 1_600_000
TARGET_SECONDS = 30 * 60


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def run(samples: int, workers: int, seed: int, out: Path | None, shard_size: int) -> dict:
    """Generate ``samples`` rows with ``workers`` processes; the measured figures."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

    tmp = None
    if out is None:
        tmp = Path(tempfile.mkdtemp(prefix="bench-datagen-"))
        out = tmp / "data"
    load_before = os.getloadavg()
    cpu0, t0 = _cpu(), time.perf_counter()
    manifest = generate_dataset(RunConfig(out, samples, seed, shard_size), workers=workers, progress=False)
    wall = time.perf_counter() - t0
    cpu = _cpu() - cpu0
    load_after = os.getloadavg()
    size = sum(p.stat().st_size for p in (out / "data").rglob("*.jsonl"))
    if tmp is not None:
        shutil.rmtree(tmp, ignore_errors=True)
    per_cpu = samples / cpu
    return {
        "samples": samples,
        "workers": workers,
        "seed": seed,
        "shard_size": shard_size,
        "wall_seconds": round(wall, 1),
        "cpu_seconds": round(cpu, 1),
        "rows_per_s_wall": round(samples / wall, 1),
        "rows_per_cpu_s": round(per_cpu, 1),
        "dedicated_2core_rows_per_s": round(2 * per_cpu, 1),
        "est_1p6M_minutes_at_measured_wall_rate": round(TARGET_ROWS / (samples / wall) / 60, 1),
        "est_1p6M_minutes_on_2_dedicated_cores": round(TARGET_ROWS / (2 * per_cpu) / 60, 1),
        "target_met_on_2_dedicated_cores": TARGET_ROWS / (2 * per_cpu) <= TARGET_SECONDS,
        "loadavg_1min_before_after": [round(load_before[0], 2), round(load_after[0], 2)],
        "cpus": os.cpu_count(),
        "bytes_per_row": round(size / samples, 1),
        "plans_validated": manifest["generator"].get("plans_validated", 0),
        "plans_rejected_by_checker": manifest["generator"].get("plans_rejected_by_checker", 0),
        "splits": manifest["splits"],
    }


def main() -> None:
    """Command line entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=50_000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--shard-size", type=int, default=5000)
    ap.add_argument(
        "--out", type=Path, default=None, help="keep the dataset here (default: a temp dir, deleted)"
    )
    ap.add_argument("--json", type=Path, default=None, help="also write the result to this file")
    a = ap.parse_args()
    result = run(a.samples, a.workers, a.seed, a.out, a.shard_size)
    text = json.dumps(result, indent=1)
    print(text)
    if a.json:
        a.json.write_text(text + "\n")


if __name__ == "__main__":
    main()
