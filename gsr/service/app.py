"""The reasoning API over HTTP (FastAPI): a thin layer over gsr's check, validate, plan and ground.

Every error a client can cause is a structured 4xx ``{"error": {"type", "message", ...}}``: malformed
JSON (400), a body over the size limit (413), invalid graphs/PDDL/steps/instructions (422), no free
worker slot in time (503). CPU-heavy handlers run in worker threads behind a semaphore.
"""

from __future__ import annotations

import asyncio
import hashlib
import time
from collections.abc import Awaitable, Callable
from functools import lru_cache
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.concurrency import run_in_threadpool

from gsr.errors import GSRError
from gsr.service.schemas import (
    CheckRequest,
    DomainRef,
    GroundRequest,
    PlanRequest,
    SolveRequest,
    StepIn,
    TaskIn,
    ValidateRequest,
)
from gsr.service.settings import ServiceSettings


class ApiError(Exception):
    """An error answered with ``status`` and a structured body."""

    def __init__(self, status: int, kind: str, message: str, **details: Any) -> None:
        super().__init__(message)
        self.status, self.kind, self.message, self.details = status, kind, message, details


def _error_body(kind: str, message: str, **details: Any) -> dict[str, Any]:
    return {"error": {"type": kind, "message": message, **details}}


# ------------------------------------------------------------------ inputs


@lru_cache(maxsize=32)
def _parse_domain_text(digest: str, text: str):  # digest keys the cache without hashing long text twice
    from gsr.pddl.parser import parse_domain

    return parse_domain(text, source="domain_pddl")


def _domain(ref: DomainRef):
    from gsr.resources import load_builtin_domain

    if ref.domain_pddl is not None:
        return _parse_domain_text(hashlib.sha1(ref.domain_pddl.encode()).hexdigest(), ref.domain_pddl)
    return load_builtin_domain(ref.domain)


def _graph(data: dict[str, Any], field: str = "scene_graph"):
    from gsr.io import scene_from_data

    return scene_from_data(data, source=field)


def _step(value: str | StepIn, where: str = "step"):
    from gsr.pddl.parser import parse_atom
    from gsr.plan_format import parse_plan
    from gsr.step import Step

    if isinstance(value, StepIn):

        def atoms(texts: list[str] | None) -> tuple | None:
            return None if texts is None else tuple(parse_atom(t, source=where) for t in texts)

        return Step(
            value.action.lower(), tuple(a.lower() for a in value.args), atoms(value.add), atoms(value.delete)
        )
    steps = parse_plan(value, source=where).steps
    if len(steps) != 1:
        raise ApiError(422, "invalid_step", f"{where}: expected exactly one step, got {len(steps)}")
    return steps[0]


def _task(req: TaskIn):
    """(domain, problem) from a PDDL problem or from scene graph + goal."""
    from gsr.facts import problem_from_graph
    from gsr.pddl.parser import parse_formula, parse_problem

    domain = _domain(req)
    if req.problem_pddl is not None:
        return domain, parse_problem(req.problem_pddl, source="problem_pddl", domain=domain)
    if req.scene_graph is None or req.goal is None:
        raise ApiError(422, "invalid_request", "give either problem_pddl, or scene_graph and goal")
    goal = parse_formula(req.goal, source="goal")
    return domain, problem_from_graph(_graph(req.scene_graph), goal, domain=domain)


def _plan_result_dict(result) -> dict[str, Any]:
    return {
        "status": result.status,
        "plan": None if result.plan is None else [str(s) for s in result.plan],
        "cost": result.cost,
        "expanded": result.expanded,
        "generated": result.generated,
        "time": result.time,
        "planner": result.planner,
        "message": result.message,
    }


# ------------------------------------------------------------------ handlers (sync, run in threads)


def handle_check(req: CheckRequest) -> dict[str, Any]:
    """Check one step against a scene graph."""
    from gsr.check import check_step
    from gsr.facts import state_from_graph

    domain = _domain(req)
    graph = _graph(req.scene_graph)
    return check_step(domain, state_from_graph(graph, domain), _step(req.step)).to_dict()


def handle_validate(req: ValidateRequest, settings: ServiceSettings) -> dict[str, Any]:
    """Validate a plan against a task."""
    from gsr.plan_format import parse_plan
    from gsr.step import Plan
    from gsr.validate import validate_plan

    domain, problem = _task(req)
    if isinstance(req.plan, str):
        plan = parse_plan(req.plan, source="plan")
    else:
        plan = Plan(tuple(_step(s, where=f"plan[{i}]") for i, s in enumerate(req.plan)))
    if len(plan) > settings.max_steps:
        raise ApiError(
            422, "too_many_steps", f"plan has {len(plan)} steps; the limit is {settings.max_steps}"
        )
    return validate_plan(domain, problem, plan).to_dict()


def handle_plan(req: PlanRequest, settings: ServiceSettings) -> dict[str, Any]:
    """Plan a task within the server's time budget."""
    from gsr.plan import PLANNERS, plan

    if req.planner not in PLANNERS or req.planner == "fd":
        offered = ", ".join(p for p in PLANNERS if p != "fd")
        raise ApiError(422, "unknown_planner", f"unknown planner {req.planner!r}; choose one of {offered}")
    timeout = min(req.timeout or settings.max_plan_seconds, settings.max_plan_seconds)
    domain, problem = _task(req)
    return _plan_result_dict(plan(domain, problem, planner=req.planner, timeout=timeout))


def handle_ground(req: GroundRequest) -> dict[str, Any]:
    """Ground an instruction into a goal formula over the graph."""
    from gsr.language import ground
    from gsr.pddl.writer import write_formula

    goal = ground(req.instruction, _graph(req.scene_graph))
    return {"goal": write_formula(goal.formula), "instruction": req.instruction}


def handle_solve(req: SolveRequest, settings: ServiceSettings) -> dict[str, Any]:
    """Instruction -> goal -> checked steps, through the reasoner loop with a server-approved backend."""
    from gsr.reason import MODES, solve

    if req.backend not in settings.backends:
        offered = ", ".join(settings.backends)
        raise ApiError(
            422, "unknown_backend", f"backend {req.backend!r} is not offered here (offered: {offered})"
        )
    if req.mode not in MODES:
        raise ApiError(422, "unknown_mode", f"unknown mode {req.mode!r}; choose one of {', '.join(MODES)}")
    timeout = min(req.timeout or settings.max_plan_seconds, settings.max_plan_seconds)
    result = solve(
        _graph(req.scene_graph), req.instruction, backend=req.backend, mode=req.mode, planner_timeout=timeout
    )
    return result.to_dict()


def handle_scene_graph(data: dict[str, Any]) -> dict[str, Any]:
    """Validate a scene graph and list the atoms it entails."""
    from gsr.facts import facts

    graph = _graph(data, field="body")
    return {
        "valid": True,
        "nodes": len(graph.nodes),
        "edges": len(graph.edges),
        "facts": sorted(map(str, facts(graph))),
    }


def list_domains() -> list[dict[str, Any]]:
    """The built-in domains with their action signatures."""
    from gsr.diagnosis import typed_text
    from gsr.resources import data_dir, load_builtin_domain

    out = []
    for path in sorted((data_dir() / "domains").glob("*.pddl")):
        domain = load_builtin_domain(path.stem)
        actions = [f"({a.name} {typed_text(a.params)})".replace(" )", ")") for a in domain.actions.values()]
        out.append(
            {
                "name": path.stem,
                "pddl_name": domain.name,
                "actions": actions,
                "predicates": len(domain.predicates),
            }
        )
    return out


# ------------------------------------------------------------------ app


def create_app(settings: ServiceSettings | None = None) -> FastAPI:
    """The FastAPI application with limits from ``settings`` (defaults: ServiceSettings())."""
    from gsr import __version__

    settings = settings or ServiceSettings()
    app = FastAPI(
        title="GSR reasoning API",
        version=__version__,
        description="Check steps, validate plans, plan and ground instructions over grounded scene graphs.",
    )
    slots = asyncio.Semaphore(settings.max_concurrent)
    app.state.settings = settings

    async def heavy(fn: Callable[..., dict[str, Any]], *args: Any) -> dict[str, Any]:
        try:
            await asyncio.wait_for(slots.acquire(), timeout=settings.queue_timeout)
        except TimeoutError:
            raise ApiError(503, "busy", "all workers are busy; retry later", retry_after=1) from None
        try:
            return await run_in_threadpool(fn, *args)
        finally:
            slots.release()

    @app.middleware("http")
    async def limit_body(request: Request, call_next: Callable[[Request], Awaitable[Any]]) -> Any:
        declared = request.headers.get("content-length")
        if declared is not None and (not declared.isdigit() or int(declared) > settings.max_body_bytes):
            return JSONResponse(
                _error_body("body_too_large", f"request body over {settings.max_body_bytes} bytes"),
                status_code=413,
            )
        if request.method == "POST" and declared is None:  # chunked upload: count what arrives
            body = b""
            async for chunk in request.stream():
                body += chunk
                if len(body) > settings.max_body_bytes:
                    return JSONResponse(
                        _error_body("body_too_large", f"request body over {settings.max_body_bytes} bytes"),
                        status_code=413,
                    )
            request._body = body  # starlette re-reads the cached body downstream
        return await call_next(request)

    @app.exception_handler(ApiError)
    async def api_error(_: Request, exc: ApiError) -> JSONResponse:
        headers = {"Retry-After": str(exc.details["retry_after"])} if "retry_after" in exc.details else None
        return JSONResponse(_error_body(exc.kind, exc.message, **exc.details), exc.status, headers=headers)

    @app.exception_handler(GSRError)
    async def gsr_error(_: Request, exc: GSRError) -> JSONResponse:
        extra: dict[str, Any] = {}
        for attr in ("unknown_words", "candidates"):  # grounding errors carry these
            value = getattr(exc, attr, None)
            if value:
                extra[attr] = value if isinstance(value, list | dict | str) else list(value)
        return JSONResponse(_error_body(type(exc).__name__, str(exc), **extra), status_code=422)

    @app.exception_handler(RequestValidationError)
    async def bad_request(_: Request, exc: RequestValidationError) -> JSONResponse:
        errors = [
            {
                "field": ".".join(str(p) for p in e.get("loc", ()) if p != "body") or "body",
                "message": e.get("msg", ""),
            }
            for e in exc.errors()
        ]
        if any(e.get("type") == "json_invalid" for e in exc.errors()):
            return JSONResponse(
                _error_body("invalid_json", "request body is not valid JSON", errors=errors), 400
            )
        return JSONResponse(
            _error_body("invalid_request", errors[0]["message"] if errors else "", errors=errors), 422
        )

    @app.get("/health")
    async def health() -> dict[str, Any]:
        return {"status": "ok", "version": __version__, "time": time.time()}

    @app.get("/v1/domains")
    async def domains() -> list[dict[str, Any]]:
        return await run_in_threadpool(list_domains)

    @app.post("/v1/check")
    async def check(req: CheckRequest) -> dict[str, Any]:
        """Check one step against a scene graph: 200 with ``ok`` and the diagnosis."""
        return await heavy(handle_check, req)

    @app.post("/v1/validate")
    async def validate(req: ValidateRequest) -> dict[str, Any]:
        """Validate a plan: 200 with ``valid``, per-step diagnoses and unmet goal literals."""
        return await heavy(handle_validate, req, settings)

    @app.post("/v1/plan")
    async def plan_endpoint(req: PlanRequest) -> dict[str, Any]:
        """Plan a PDDL problem or a scene graph + goal within the server's time budget."""
        return await heavy(handle_plan, req, settings)

    @app.post("/v1/ground")
    async def ground_endpoint(req: GroundRequest) -> dict[str, Any]:
        """Ground an instruction to a goal formula (422 names unknown words or ambiguous objects)."""
        return await heavy(handle_ground, req)

    @app.post("/v1/solve")
    async def solve(req: SolveRequest) -> dict[str, Any]:
        """Instruction -> goal -> plan, every step checked."""
        return await heavy(handle_solve, req, settings)

    @app.post("/v1/scene-graph/validate")
    async def scene_graph_validate(body: dict[str, Any]) -> dict[str, Any]:
        """Validate a scene graph (JSON or GSR-Bench message); 422 names the offending field."""
        return await heavy(handle_scene_graph, body)

    return app
