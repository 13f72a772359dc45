"""Request ids, /metrics, JSON logs, and stored scenes (send a scene once, check many steps)."""

from __future__ import annotations

import json
import logging
import re

from gsr.service.metrics import Metrics
from gsr.service.middleware import JsonFormatter, configure_logging
from tests.gsr.service.conftest import SCENE

CHECK = {"scene_graph": SCENE, "step": "(pick red_cube1 table)"}


def test_request_id_is_echoed_or_made(make_client) -> None:
    client = make_client()
    r = client.post("/v1/check", json=CHECK, headers={"x-request-id": "agent-7.step-3"})
    assert r.headers["x-request-id"] == "agent-7.step-3"
    made = client.post("/v1/check", json=CHECK, headers={"x-request-id": "bad id\twith spaces"})
    assert re.fullmatch(r"[0-9a-f]{32}", made.headers["x-request-id"])
    err = client.post("/v1/check", json={"scene_graph": SCENE}, headers={"x-request-id": "req-1"})
    assert err.status_code == 422 and err.json()["error"]["request_id"] == "req-1"
    assert client.get("/health").headers["x-request-id"]


def test_metrics_in_prometheus_text_format(make_client) -> None:
    client = make_client(max_body_bytes=5_000)
    for _ in range(3):
        client.post("/v1/check", json=CHECK)
    client.post("/v1/check", json={**CHECK, "pad": "x" * 6_000})
    r = client.get("/metrics")
    assert r.status_code == 200 and r.headers["content-type"].startswith("text/plain; version=0.0.4")
    text = r.text
    assert 'gsr_requests_total{endpoint="/v1/check",method="POST",status="200"} 3' in text
    assert 'gsr_requests_total{endpoint="/v1/check",method="POST",status="413"} 1' in text
    assert 'gsr_rejections_total{reason="max_body_bytes"} 1' in text
    assert "# TYPE gsr_request_duration_seconds histogram" in text
    buckets = re.findall(
        r'gsr_request_duration_seconds_bucket\{endpoint="/v1/check",le="([^"]+)"\} (\S+)', text
    )
    counts = [float(n) for _, n in buckets]
    assert buckets[-1][0] == "+Inf" and counts[-1] == 4 and counts == sorted(counts)  # cumulative
    assert re.search(r'gsr_process_resident_bytes\{pid="\d+"\} [1-9]', text)
    for line in text.splitlines():  # every sample line is `name{labels} value`
        assert line.startswith("#") or re.fullmatch(r"[a-z_]+(\{[^}]*\})? [0-9.e+-]+", line), line


def test_metrics_sum_the_processes_that_share_a_state_dir(tmp_path) -> None:
    other = Metrics(None)  # another uvicorn worker's counts, in its own snapshot file
    other.observe_request("/v1/check", "POST", 200, 0.002)
    snapshot = json.dumps(other.snapshot())
    (tmp_path / "metrics-1.json").write_text(snapshot)  # pid 1 is alive
    (tmp_path / "metrics-999999999.json").write_text(snapshot)  # a process that is gone
    mine = Metrics(tmp_path)
    assert not (tmp_path / "metrics-999999999.json").exists()  # dropped at start
    mine.observe_request("/v1/check", "POST", 200, 0.3)
    text = mine.render()
    assert 'gsr_requests_total{endpoint="/v1/check",method="POST",status="200"} 2' in text
    assert 'gsr_request_duration_seconds_count{endpoint="/v1/check"} 2' in text
    assert 'gsr_request_duration_seconds_bucket{endpoint="/v1/check",le="0.0025"} 1' in text


def test_json_logs_carry_the_request_id(make_client, capsys) -> None:
    configure_logging(json_lines=True)
    try:
        client = make_client()
        client.post("/v1/check", json=CHECK, headers={"x-request-id": "log-me-1"})
        lines = [json.loads(ln) for ln in capsys.readouterr().err.splitlines() if ln.startswith("{")]
    finally:
        logging.getLogger("gsr.service").handlers.clear()
    entry = next(e for e in lines if e.get("request_id") == "log-me-1")
    assert entry["path"] == "/v1/check" and entry["status"] == 200 and entry["level"] == "info"
    assert entry["ms"] >= 0 and entry["time"].endswith("Z")
    record = logging.LogRecord("gsr.service", logging.ERROR, __file__, 1, "boom %s", ("x",), None)
    assert json.loads(JsonFormatter().format(record))["message"] == "boom x"


def test_stored_scene_checks_like_the_inline_graph(make_client) -> None:
    client = make_client()
    stored = client.post("/v1/scenes", json=SCENE)
    assert stored.status_code == 201
    scene_id = stored.json()["scene_id"]
    assert stored.json()["nodes"] == 4
    assert client.post("/v1/scenes", json=dict(reversed(list(SCENE.items())))).json()["scene_id"] == scene_id
    for step in ("(pick red_cube1 table)", "(pick blue_box table)"):
        inline = client.post("/v1/check", json={"scene_graph": SCENE, "step": step}).json()
        by_id = client.post("/v1/check", json={"scene_id": scene_id, "step": step}).json()
        assert by_id == inline
    plan = {"goal": "(holding red_cube1)", "plan": ["(pick red_cube1 table)"]}
    assert client.post("/v1/validate", json={"scene_id": scene_id, **plan}).json()["valid"] is True
    assert (
        client.get(f"/v1/scenes/{scene_id}").json()["facts"]
        == client.post("/v1/scene-graph/validate", json=SCENE).json()["facts"]
    )
    missing = client.post("/v1/check", json={"scene_id": "f" * 32, "step": "(pick red_cube1 table)"})
    assert missing.status_code == 404 and missing.json()["error"]["type"] == "unknown_scene"
    both = client.post("/v1/check", json={"scene_id": scene_id, **CHECK})
    assert both.status_code == 422
    assert client.get("/v1/scenes/..%2f..%2fetc%2fpasswd").status_code == 404
    # another server process over the same state directory finds the scene on disk
    other = make_client()
    assert other.post("/v1/check", json={"scene_id": scene_id, "step": "(pick red_cube1 table)"}).json()["ok"]
    assert 'gsr_scene_cache_total{result="disk"} 1' in other.get("/metrics").text
