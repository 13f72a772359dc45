"""Load test of the reasoning service on localhost: N requests from C concurrent clients, p50/p99 latency.

Run: ``python benchmarks/bench_service.py [--requests 1000] [--concurrency 32] [--workers 1] [--json]``.
Starts ``gsr serve`` (uvicorn) on a free loopback port, waits for /health, then C asyncio clients send a
fixed, seeded mix of requests (check valid/invalid steps, validate plans, plan small tasks, validate scene
graphs, ground instructions when the grounder is installed, plus deliberately bad requests that must get
4xx). Reports per-endpoint and overall latency percentiles, throughput and the count of 5xx answers
(the target is zero). The server is stopped at the end, whatever happens.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

import httpx

SCENE = {
    "nodes": [
        "table",
        "short_cabinet",
        "short_cabinet/drawer_high(closed)",
        "short_cabinet/drawer_middle(closed)",
        "short_cabinet/drawer_low(closed)",
        "blue_box",
        "red_box",
        "red_cube1",
        "red_cube2",
        "blue_cube1",
        "yellow_mug1",
    ],
    "edges": [
        "short_cabinet(on)table",
        "blue_box(on)table",
        "red_box(on)table",
        "red_cube1(on)table",
        "red_cube2(on)blue_box",
        "blue_cube1(on)table",
        "yellow_mug1(on)table",
    ],
}


def _requests(n: int, seed: int, with_ground: bool) -> list[tuple[str, str, str, int]]:
    """(name, path, json body, expected status class) for n requests, seeded."""
    kinds = [
        ("check_ok", "/v1/check", {"scene_graph": SCENE, "step": "(pick red_cube1 table)"}, 2),
        ("check_invalid", "/v1/check", {"scene_graph": SCENE, "step": "(pick blue_box table)"}, 2),
        (
            "validate",
            "/v1/validate",
            {
                "scene_graph": SCENE,
                "goal": "(and (in red_cube1 red_box) (in blue_cube1 blue_box))",
                "plan": [
                    "(pick red_cube1 table)",
                    "(place_in red_cube1 red_box)",
                    "(pick blue_cube1 table)",
                    "(place_in blue_cube1 blue_box)",
                ],
            },
            2,
        ),
        (
            "plan",
            "/v1/plan",
            {
                "scene_graph": SCENE,
                "goal": "(and (in red_cube1 short_cabinet/drawer_low) (in yellow_mug1 short_cabinet/drawer_middle))",
            },
            2,
        ),
        ("scene_graph", "/v1/scene-graph/validate", SCENE, 2),
        ("bad_step", "/v1/check", {"scene_graph": SCENE, "step": "(pick red_cube1"}, 4),
        ("bad_graph", "/v1/scene-graph/validate", {"nodes": ["a"], "edges": ["a(on)ghost"]}, 4),
    ]
    if with_ground:
        kinds.append(
            (
                "ground",
                "/v1/ground",
                {"scene_graph": SCENE, "instruction": "put all red cubes into the red box"},
                2,
            )
        )
    rng = random.Random(seed)
    return [(k[0], k[1], json.dumps(k[2]), k[3]) for k in (rng.choice(kinds) for _ in range(n))]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def _run(base: str, reqs: list[tuple[str, str, str, int]], concurrency: int) -> tuple[list, float]:
    queue: asyncio.Queue = asyncio.Queue()
    for r in reqs:
        queue.put_nowait(r)
    results: list[tuple[str, float, int, int]] = []
    limits = httpx.Limits(max_connections=concurrency, max_keepalive_connections=concurrency)

    async def client_loop(client: httpx.AsyncClient) -> None:
        while True:
            try:
                name, path, body, expect = queue.get_nowait()
            except asyncio.QueueEmpty:
                return
            t0 = time.perf_counter()
            try:
                resp = await client.post(path, content=body, headers={"content-type": "application/json"})
                status = resp.status_code
            except httpx.HTTPError:
                status = 599  # transport failure counts as a server error
            results.append((name, time.perf_counter() - t0, status, expect))

    start = time.perf_counter()
    async with httpx.AsyncClient(base_url=base, timeout=60.0, limits=limits) as client:
        await asyncio.gather(*(client_loop(client) for _ in range(concurrency)))
    return results, time.perf_counter() - start


def _pct(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def main() -> int:
    """Run the load test; exit 1 when any request got a 5xx or an unexpected status class."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=1000)
    ap.add_argument("--concurrency", type=int, default=32)
    ap.add_argument("--workers", type=int, default=1, help="uvicorn worker processes")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()

    try:
        import gsr.language  # noqa: F401

        with_ground = True
    except ImportError:
        with_ground = False
    port = _free_port()
    gsr_bin = Path(sys.executable).with_name("gsr")
    cmd = [
        str(gsr_bin),
        "serve",
        "--port",
        str(port),
        "--workers",
        str(args.workers),
        "--max-concurrent",
        "32",
    ]
    server = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=dict(os.environ))
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.time() + 60
        while True:
            try:
                if httpx.get(f"{base}/health", timeout=1.0).status_code == 200:
                    break
            except httpx.HTTPError:
                pass
            if server.poll() is not None or time.time() > deadline:
                err = server.stderr.read().decode() if server.stderr else ""
                print(f"server did not start: {err[-2000:]}", file=sys.stderr)
                return 1
            time.sleep(0.2)
        # warm up (domain parse, first imports) outside the measurement
        asyncio.run(_run(base, _requests(20, args.seed + 1, with_ground), 4))
        results, wall = asyncio.run(
            _run(base, _requests(args.requests, args.seed, with_ground), args.concurrency)
        )
    finally:
        server.terminate()
        try:
            server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()

    server_errors = sum(1 for _, _, s, _ in results if s >= 500)
    unexpected = sum(1 for _, _, s, e in results if s // 100 != e)
    lat = [t for _, t, _, _ in results]
    per: dict[str, dict[str, float]] = {}
    for name in sorted({r[0] for r in results}):
        ts = [t for n, t, _, _ in results if n == name]
        per[name] = {"n": len(ts), "p50_ms": _pct(ts, 0.5) * 1e3, "p99_ms": _pct(ts, 0.99) * 1e3}
    summary = {
        "requests": len(results),
        "concurrency": args.concurrency,
        "workers": args.workers,
        "wall_s": wall,
        "throughput_rps": len(results) / wall,
        "p50_ms": _pct(lat, 0.5) * 1e3,
        "p99_ms": _pct(lat, 0.99) * 1e3,
        "mean_ms": statistics.fmean(lat) * 1e3,
        "server_errors": server_errors,
        "unexpected_status": unexpected,
        "endpoints": per,
    }
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(
            f"{summary['requests']} requests, {args.concurrency} clients, {args.workers} worker(s): "
            f"{summary['throughput_rps']:.0f} req/s, p50 {summary['p50_ms']:.1f} ms, p99 {summary['p99_ms']:.1f} ms, "
            f"5xx {server_errors}, unexpected status {unexpected}"
        )
        for name, v in per.items():
            print(f"  {name:14s} n={int(v['n']):4d}  p50 {v['p50_ms']:7.1f} ms  p99 {v['p99_ms']:7.1f} ms")
    return 0 if server_errors == 0 and unexpected == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
