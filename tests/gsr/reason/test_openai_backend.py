"""The openai backend against a real local HTTP server speaking the OpenAI chat API (scripted replies)."""

from __future__ import annotations

import json
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest

from gsr.reason import BackendError, make_backend, solve

from .conftest import PICK, PLACE


class FakeOpenAI:
    """A local /v1/chat/completions server that replays scripted answers and records the requests."""

    def __init__(self, replies, status=200):
        self.replies = list(replies)
        self.requests = []
        self.status = status
        fake = self

        class Handler(BaseHTTPRequestHandler):
            def do_POST(self):
                body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
                fake.requests.append((self.path, dict(self.headers), body))
                if fake.status != 200:
                    self._send(fake.status, {"error": {"message": "overloaded"}})
                    return
                text = fake.replies.pop(0) if fake.replies else ""
                self._send(
                    200,
                    {
                        "id": "x",
                        "object": "chat.completion",
                        "choices": [
                            {
                                "index": 0,
                                "message": {"role": "assistant", "content": text},
                                "finish_reason": "stop",
                            }
                        ],
                    },
                )

            def _send(self, code, payload):
                data = json.dumps(payload).encode()
                self.send_response(code)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def log_message(self, *args):
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}/v1"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.server.shutdown()
        self.server.server_close()


def test_repair_after_diagnosis_over_http(graph, domain, box_goal):
    with FakeOpenAI(["```\n(pick red_cube1 blue_box)\n```", PICK, PLACE]) as server:
        backend = make_backend("openai:tiny-test", base_url=server.url, api_key="sk-test")
        result = solve(graph, box_goal.text, backend, goal=box_goal, domain=domain)
    assert result.success and result.repairs == 1 and result.backend == "openai:tiny-test"
    path, headers, body = server.requests[1]
    assert path == "/v1/chat/completions" and headers["Authorization"] == "Bearer sk-test"
    assert body["model"] == "tiny-test" and body["temperature"] == 0.0
    assert [m["role"] for m in body["messages"]] == ["system", "user"]
    assert "precondition (or (on red_cube1 blue_box)" in body["messages"][1]["content"]


def test_environment_configuration_and_goal_mode(graph, domain, monkeypatch):
    with FakeOpenAI(["(in red_cube1 blue_box)"]) as server:
        monkeypatch.setenv("OPENAI_BASE_URL", server.url)
        monkeypatch.delenv("OPENAI_API_KEY", raising=False)
        result = solve(graph, "put the red cube in the blue box", "openai:m", mode="goal", domain=domain)
    assert result.success and result.goal_source == "model"
    assert "Authorization" not in server.requests[0][1]


def test_http_errors_become_backend_errors(graph, domain, box_goal):
    with FakeOpenAI([], status=503) as server:
        backend = make_backend("openai:m", base_url=server.url, retries=1)
        with pytest.raises(BackendError, match="HTTP 503"):
            backend.complete(__import__("gsr.reason", fromlist=["Prompt"]).Prompt("s", "u"))
        result = solve(graph, "x", backend, goal=box_goal, domain=domain)
    assert result.status == "backend_error" and "HTTP 503" in result.message
    assert len(server.requests) == 4  # two calls, each retried once


def test_unreachable_server(graph, domain, box_goal):
    backend = make_backend("openai:m", base_url="http://127.0.0.1:9/v1", retries=0, timeout=2)
    result = solve(graph, "x", backend, goal=box_goal, domain=domain)
    assert result.status == "backend_error" and "request failed" in result.message
