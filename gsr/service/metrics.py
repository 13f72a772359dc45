"""Request metrics in the Prometheus text format, summed over a server's processes.

Each server process counts in memory and writes a snapshot (``metrics-<pid>.json`` in the state
directory) at most once a second and whenever /metrics is asked; /metrics sums every snapshot, so
the answer covers all uvicorn workers whichever one serves the scrape (the others' figures may be up
to a second old). Counters of processes that ended stay in the sums; gauges count live processes only.
"""

from __future__ import annotations

import json
import os
import time
from collections import defaultdict
from pathlib import Path

BUCKETS = (0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0)
HELP = {
    "gsr_requests_total": ("counter", "HTTP requests answered, by endpoint, method and status code."),
    "gsr_request_duration_seconds": ("histogram", "Time from request start to response, by endpoint."),
    "gsr_rejections_total": ("counter", "Requests refused by a limit or by authentication, by reason."),
    "gsr_worker_restarts_total": ("counter", "Isolated worker processes stopped and replaced, by reason."),
    "gsr_scene_cache_total": ("counter", "Stored-scene lookups, by result (memory, disk, miss)."),
    "gsr_requests_in_flight": ("gauge", "Requests being handled now."),
    "gsr_process_resident_bytes": ("gauge", "Resident memory of each server process."),
}


def _key(name: str, labels: dict[str, str]) -> str:
    if not labels:
        return name
    inner = ",".join(f'{k}="{_escape(str(v))}"' for k, v in sorted(labels.items()))
    return f"{name}{{{inner}}}"


def _escape(value: str) -> str:
    return value.replace("\\", "\\\\").replace("\n", "\\n").replace('"', '\\"')


class Metrics:
    """One process's counters, latency histograms and gauges."""

    def __init__(self, directory: Path | None) -> None:
        self.directory = directory
        self.counters: dict[str, float] = defaultdict(float)
        self.histograms: dict[str, list[float]] = {}  # endpoint -> bucket counts..., sum, count
        self.in_flight = 0
        self._last_write = 0.0
        if directory is not None:
            directory.mkdir(parents=True, exist_ok=True)
            for path in directory.glob("metrics-*.json"):  # snapshots of processes long gone
                if not _alive(_pid_of(path)):
                    path.unlink(missing_ok=True)

    def inc(self, name: str, value: float = 1.0, **labels: str) -> None:
        self.counters[_key(name, labels)] += value

    def observe_request(self, endpoint: str, method: str, status: int, seconds: float) -> None:
        self.inc("gsr_requests_total", endpoint=endpoint, method=method, status=str(status))
        h = self.histograms.get(endpoint)
        if h is None:
            h = self.histograms[endpoint] = [0.0] * (len(BUCKETS) + 2)
        for i, bound in enumerate(BUCKETS):
            if seconds <= bound:
                h[i] += 1
                break
        h[-2] += seconds
        h[-1] += 1
        now = time.monotonic()
        if now - self._last_write > 1.0:
            self._last_write = now
            self.write_snapshot()

    def snapshot(self) -> dict:
        return {
            "counters": dict(self.counters),
            "histograms": self.histograms,
            "gauges": {
                "gsr_requests_in_flight": self.in_flight,
                _key("gsr_process_resident_bytes", {"pid": str(os.getpid())}): _rss_bytes(),
            },
        }

    def write_snapshot(self) -> None:
        if self.directory is None:
            return
        path = self.directory / f"metrics-{os.getpid()}.json"
        tmp = path.with_suffix(".tmp")
        try:
            tmp.write_text(json.dumps(self.snapshot()))
            os.replace(tmp, path)
        except OSError:
            pass  # metrics must never fail a request

    def render(self) -> str:
        """The Prometheus text exposition of all live and past processes' snapshots."""
        snaps = [self.snapshot()]
        if self.directory is not None:
            self.write_snapshot()
            snaps = []
            for path in sorted(self.directory.glob("metrics-*.json")):
                try:
                    snap = json.loads(path.read_text())
                except (OSError, ValueError):
                    continue
                if not _alive(_pid_of(path)):
                    snap["gauges"] = {}
                snaps.append(snap)
        counters: dict[str, float] = defaultdict(float)
        gauges: dict[str, float] = defaultdict(float)
        hists: dict[str, list[float]] = {}
        for snap in snaps:
            for k, v in snap.get("counters", {}).items():
                counters[k] += v
            for k, v in snap.get("gauges", {}).items():
                gauges[k] += v
            for ep, h in snap.get("histograms", {}).items():
                acc = hists.setdefault(ep, [0.0] * len(h))
                for i, v in enumerate(h):
                    acc[i] += v
        lines: list[str] = []
        for name, (kind, text) in HELP.items():
            lines += [f"# HELP {name} {text}", f"# TYPE {name} {kind}"]
            if kind == "histogram":
                for ep, h in sorted(hists.items()):
                    running = 0.0
                    for bound, n in zip(BUCKETS, h, strict=False):
                        running += n
                        lines.append(f'{name}_bucket{{endpoint="{_escape(ep)}",le="{bound:g}"}} {running:g}')
                    lines.append(f'{name}_bucket{{endpoint="{_escape(ep)}",le="+Inf"}} {h[-1]:g}')
                    lines.append(f'{name}_sum{{endpoint="{_escape(ep)}"}} {h[-2]:.6f}')
                    lines.append(f'{name}_count{{endpoint="{_escape(ep)}"}} {h[-1]:g}')
                continue
            source = counters if kind == "counter" else gauges
            for key in sorted(k for k in source if k == name or k.startswith(name + "{")):
                lines.append(f"{key} {source[key]:g}")
        return "\n".join(lines) + "\n"


def _pid_of(path: Path) -> int:
    try:
        return int(path.stem.split("-", 1)[1])
    except (IndexError, ValueError):
        return -1


def _alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _rss_bytes() -> int:
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0
