"""The HTTP reasoning API: every endpoint, its limits, and structured 4xx errors on bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from gsr.service import ServiceSettings, create_app

SCENE = {
    "nodes": ["table", "blue_box", "red_box", "red_cube1", "red_cube2"],
    "edges": ["blue_box(on)table", "red_box(on)table", "red_cube1(on)table", "red_cube2(on)blue_box"],
}


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory):
    settings = ServiceSettings(
        max_plan_seconds=5.0, max_body_bytes=64_000, state_dir=str(tmp_path_factory.mktemp("state"))
    )
    app = create_app(settings)
    yield TestClient(app)
    app.state.pool.close()


def test_health_and_openapi(client: TestClient) -> None:
    assert client.get("/health").json()["status"] == "ok"
    spec = client.get("/openapi.json").json()
    for path in (
        "/v1/check",
        "/v1/validate",
        "/v1/plan",
        "/v1/ground",
        "/v1/solve",
        "/v1/scene-graph/validate",
    ):
        assert path in spec["paths"], path


def test_domains_lists_tabletop_actions(client: TestClient) -> None:
    domains = {d["name"]: d for d in client.get("/v1/domains").json()}
    assert "tabletop" in domains
    assert any(a.startswith("(pick ") for a in domains["tabletop"]["actions"])


def test_check_valid_and_invalid_step(client: TestClient) -> None:
    ok = client.post("/v1/check", json={"scene_graph": SCENE, "step": "(pick red_cube1 table)"})
    assert ok.status_code == 200 and ok.json()["ok"] is True
    assert "(holding red_cube1)" in ok.json()["effects"]["add"]
    # the box has a cube on it: the checker explains why it cannot be picked
    bad = client.post("/v1/check", json={"scene_graph": SCENE, "step": "(pick blue_box table)"})
    assert bad.status_code == 200
    body = bad.json()
    assert body["ok"] is False and body["reasons"]
    assert "red_cube2" in json.dumps(body)


def test_check_step_object_with_wrong_claim(client: TestClient) -> None:
    step = {
        "action": "pick",
        "args": ["red_cube1", "table"],
        "add": ["(on red_cube1 blue_box)"],
        "delete": [],
    }
    body = client.post("/v1/check", json={"scene_graph": SCENE, "step": step}).json()
    assert body["ok"] is False
    assert any("effect" in r["kind"] for r in body["reasons"])


def test_validate_plan_on_graph_and_goal(client: TestClient) -> None:
    req = {
        "scene_graph": SCENE,
        "goal": "(in red_cube1 red_box)",
        "plan": ["(pick red_cube1 table)", "(place_in red_cube1 red_box)"],
    }
    body = client.post("/v1/validate", json=req).json()
    assert body["valid"] is True, body
    req["plan"] = "(pick red_cube1 table)\n"
    body = client.post("/v1/validate", json=req).json()
    assert body["valid"] is False and body["goal_reached"] is False


def test_plan_pddl_problem_and_graph(client: TestClient, pddl_dir: Path) -> None:
    dom = (pddl_dir / "blocks" / "domain.pddl").read_text()
    prob = (pddl_dir / "blocks" / "probBLOCKS-4-0.pddl").read_text()
    body = client.post("/v1/plan", json={"domain_pddl": dom, "problem_pddl": prob}).json()
    assert body["status"] == "solved" and len(body["plan"]) >= 1
    body = client.post("/v1/plan", json={"scene_graph": SCENE, "goal": "(in red_cube1 red_box)"}).json()
    assert body["status"] == "solved"
    assert body["plan"][-1].startswith("(place_in red_cube1 red_box")


def test_plan_unknown_planner_and_missing_task(client: TestClient) -> None:
    r = client.post(
        "/v1/plan", json={"scene_graph": SCENE, "goal": "(in red_cube1 blue_box)", "planner": "magic"}
    )
    assert r.status_code == 422 and r.json()["error"]["type"] == "unknown_planner"
    r = client.post("/v1/plan", json={"scene_graph": SCENE})
    assert r.status_code == 422 and "goal" in r.json()["error"]["message"]


@pytest.mark.parametrize(
    ("payload", "status", "kind"),
    [
        ("{not json", 400, "invalid_json"),
        (json.dumps({"scene_graph": SCENE}), 422, "invalid_request"),  # step missing
        (json.dumps({"scene_graph": SCENE, "step": "(pick red_cube1"}), 422, "ParseError"),
        (
            json.dumps({"scene_graph": {"nodes": ["a"], "edges": ["a(on)zz"]}, "step": "(pick a t)"}),
            422,
            "GSRError",
        ),
        (
            json.dumps({"scene_graph": SCENE, "step": "(pick red_cube1 table)", "domain": "nope"}),
            422,
            "GSRError",
        ),
    ],
)
def test_bad_input_is_structured_4xx(client: TestClient, payload: str, status: int, kind: str) -> None:
    r = client.post("/v1/check", content=payload, headers={"content-type": "application/json"})
    assert r.status_code == status, r.text
    err = r.json()["error"]
    assert err["type"] == kind and err["message"]


def test_scene_graph_validate(client: TestClient) -> None:
    body = client.post("/v1/scene-graph/validate", json=SCENE).json()
    assert body["valid"] and body["nodes"] == 5 and "(on red_cube2 blue_box)" in body["facts"]
    r = client.post(
        "/v1/scene-graph/validate",
        json={
            "nodes": [{"id": "a", "category": "cube"}],
            "edges": [{"source": "a", "relation": "on", "target": "ghost"}],
        },
    )
    assert r.status_code == 422 and "ghost" in r.json()["error"]["message"]


def test_planner_stops_at_the_requested_timeout(client: TestClient, pddl_dir: Path) -> None:
    dom = (pddl_dir / "blocks" / "domain.pddl").read_text()
    prob = (pddl_dir / "blocks" / "probBLOCKS-14-0.pddl").read_text()
    req = {"domain_pddl": dom, "problem_pddl": prob, "planner": "astar-blind", "timeout": 0.05}
    body = client.post("/v1/plan", json=req).json()
    assert body["status"] == "timeout" and body["time"] < 2.0


GROUND_SCENE = {
    "nodes": ["table", "blue_box", "red_box", "red_cube1", "red_cube2", "blue_cube1"],
    "edges": [
        "blue_box(on)table",
        "red_box(on)table",
        "red_cube1(on)table",
        "red_cube2(on)table",
        "blue_cube1(on)table",
    ],
}


def test_ground_and_its_errors(client: TestClient) -> None:
    ok = client.post(
        "/v1/ground", json={"scene_graph": GROUND_SCENE, "instruction": "put all red cubes in the red box"}
    )
    assert ok.status_code == 200 and "red_box" in ok.json()["goal"]
    unknown = client.post(
        "/v1/ground", json={"scene_graph": GROUND_SCENE, "instruction": "frobnicate the zorp"}
    )
    assert unknown.status_code == 422
    assert set(unknown.json()["error"]["unknown_words"]) == {"frobnicate", "zorp"}
    ambiguous = client.post(
        "/v1/ground", json={"scene_graph": GROUND_SCENE, "instruction": "put the cube in the box"}
    )
    assert ambiguous.status_code == 422 and "red_cube1" in ambiguous.json()["error"]["candidates"]


@pytest.mark.parametrize("mode", ["goal", "steps", "hybrid"])
def test_solve_gives_checked_steps_reaching_the_goal(client: TestClient, mode: str) -> None:
    body = client.post(
        "/v1/solve",
        json={"scene_graph": GROUND_SCENE, "instruction": "put all red cubes in the red box", "mode": mode},
    ).json()
    assert body["status"] == "solved" and body["success"] is True
    moved = [s["step"] for s in body["steps"] if s["step"].startswith("(place_in")]
    assert len(moved) == 2 and all("red_box" in m for m in moved)


def test_solve_only_offers_server_backends(client: TestClient) -> None:
    r = client.post(
        "/v1/solve",
        json={
            "scene_graph": GROUND_SCENE,
            "instruction": "put all red cubes in the red box",
            "backend": "openai:x",
        },
    )
    assert r.status_code == 422 and r.json()["error"]["type"] == "unknown_backend"
