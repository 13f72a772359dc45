"""API keys: every endpoint refuses a missing or wrong key with a JSON 401 and serves the right one;
/health stays open; keys come from the environment or a key file; gsr serve will not expose an
unauthenticated server beyond loopback."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.errors import GSRError
from gsr.service.middleware import KeyCheck, RejectedError
from gsr.service.serve import is_loopback, serve
from gsr.service.settings import ServiceSettings
from tests.gsr.service.conftest import SCENE

KEY = "k" * 20 + "-first"
OTHER = "second-key-0123456789"
ENDPOINTS = [
    ("GET", "/v1/domains", None, 200),
    ("GET", "/metrics", None, 200),
    ("GET", "/openapi.json", None, 200),
    ("POST", "/v1/check", {"scene_graph": SCENE, "step": "(pick red_cube1 table)"}, 200),
    (
        "POST",
        "/v1/validate",
        {"scene_graph": SCENE, "goal": "(holding red_cube1)", "plan": ["(pick red_cube1 table)"]},
        200,
    ),
    ("POST", "/v1/plan", {"scene_graph": SCENE, "goal": "(holding red_cube1)"}, 200),
    ("POST", "/v1/ground", {"scene_graph": SCENE, "instruction": "put red_cube1 in the blue box"}, 200),
    ("POST", "/v1/solve", {"scene_graph": SCENE, "instruction": "put red_cube1 in the blue box"}, 200),
    ("POST", "/v1/scene-graph/validate", SCENE, 200),
    ("POST", "/v1/scenes", SCENE, 201),
    ("GET", "/v1/scenes/{scene_id}", None, 200),
]


@pytest.fixture
def client(make_client):
    return make_client(api_keys=(KEY, OTHER))


def _call(client, method: str, path: str, body, headers: dict[str, str]):
    if "{scene_id}" in path:
        stored = client.post("/v1/scenes", json=SCENE, headers={"authorization": f"Bearer {KEY}"})
        path = path.format(scene_id=stored.json()["scene_id"])
    return client.request(method, path, json=body, headers=headers)


@pytest.mark.parametrize(("method", "path", "body", "status"), ENDPOINTS, ids=[e[1] for e in ENDPOINTS])
def test_every_endpoint_needs_a_valid_key(client, method: str, path: str, body, status: int) -> None:
    for headers, why in (
        ({}, "required"),
        ({"authorization": "Bearer wrong-key-but-long-enough"}, "invalid"),
        ({"authorization": f"Basic {KEY}"}, "Bearer"),
        ({"authorization": "Bearer "}, "Bearer"),
    ):
        r = _call(client, method, path, body, headers)
        assert r.status_code == 401, (path, headers, r.text)
        err = r.json()["error"]
        assert err["type"] == "unauthorized" and why in err["message"] and err["request_id"]
        assert r.headers["www-authenticate"].startswith("Bearer")
    for key in (KEY, OTHER):
        r = _call(client, method, path, body, {"authorization": f"Bearer {key}"})
        assert r.status_code == status, (path, r.text)


@pytest.mark.parametrize(("method", "path", "body", "status"), ENDPOINTS, ids=[e[1] for e in ENDPOINTS])
def test_without_keys_every_endpoint_is_open(make_client, method: str, path: str, body, status: int) -> None:
    client = make_client()
    r = client.request(
        method,
        path.replace("{scene_id}", client.post("/v1/scenes", json=SCENE).json()["scene_id"]),
        json=body,
    )
    assert r.status_code == status, r.text


def test_health_is_open_and_rejections_are_counted(client) -> None:
    assert client.get("/health").status_code == 200
    client.get("/v1/domains", headers={"authorization": "Bearer nope-nope-nope-nope"})
    metrics = client.get("/metrics", headers={"authorization": f"Bearer {KEY}"}).text
    assert 'gsr_rejections_total{reason="unauthorized"}' in metrics


def test_key_check_compares_digests() -> None:
    check = KeyCheck((KEY,))
    check.verify(f"Bearer {KEY}")
    check.verify(f"bearer   {KEY}  ")  # scheme is case-insensitive, spaces around the key ignored
    for bad in (KEY[:-1], KEY + "x", KEY.upper()):
        with pytest.raises(RejectedError):
            check.verify(f"Bearer {bad}")


def test_keys_from_environment_and_file(tmp_path: Path) -> None:
    key_file = tmp_path / "keys"
    key_file.write_text(f"# service keys\n{OTHER}\n\n  {KEY}  \n")
    env = {"GSR_SERVICE_API_KEYS": f"{KEY}, extra-key-abcdefghijk", "GSR_SERVICE_API_KEY_FILE": str(key_file)}
    assert ServiceSettings.from_env(env).api_keys == (KEY, "extra-key-abcdefghijk", OTHER)
    with pytest.raises(GSRError, match="at least 16"):
        ServiceSettings.from_env({"GSR_SERVICE_API_KEYS": "short"})
    with pytest.raises(GSRError, match="cannot read the API key file"):
        ServiceSettings.from_env({"GSR_SERVICE_API_KEY_FILE": str(tmp_path / "missing")})
    with pytest.raises(GSRError, match="GSR_SERVICE_MAX_NODES"):
        ServiceSettings.from_env({"GSR_SERVICE_MAX_NODES": "many"})


def test_public_bind_needs_keys_or_insecure(monkeypatch: pytest.MonkeyPatch) -> None:
    assert is_loopback("127.0.0.1") and is_loopback("::1") and is_loopback("localhost")
    assert not is_loopback("0.0.0.0") and not is_loopback("10.1.2.3") and not is_loopback("example.org")
    monkeypatch.delenv("GSR_SERVICE_API_KEYS", raising=False)
    monkeypatch.delenv("GSR_SERVICE_API_KEY_FILE", raising=False)
    with pytest.raises(GSRError, match=r"refusing to serve on 0\.0\.0\.0 without API keys"):
        serve("0.0.0.0", 8000)
