"""The reasoning API over HTTP (FastAPI): a thin layer over gsr's check, validate, plan and ground.

Every error a client can cause is a structured 4xx ``{"error": {"type", "message", ...}}`` with the
request id; a refusal by a limit names the limit's variable. Where a request runs:

- check / validate over a built-in domain, scene storage: in this process (bounded by the size
  limits); small ones inline, larger ones in a thread, at most ``max_concurrent`` at once;
- plan, solve, ground, and anything over user PDDL: in an isolated worker process that is killed
  when the request's time budget runs out (``gsr.service.pool``).
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import logging
import time
from collections.abc import Callable
from contextlib import asynccontextmanager
from typing import Any

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse, PlainTextResponse
from pydantic import BaseModel, TypeAdapter, ValidationError
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException as StarletteHTTPException

from gsr import __version__
from gsr.errors import GSRError
from gsr.service.handlers import (
    ApiError,
    Scene,
    api_error_from,
    builtin_domain,
    check_instruction,
    check_plan_length,
    check_scene_size,
    error_body,
    list_domains,
    run_handler,
    scene_summary,
)
from gsr.service.metrics import Metrics
from gsr.service.middleware import ServiceMiddleware, rejection_reason
from gsr.service.pool import IsolatedPool
from gsr.service.scenes import SceneStore
from gsr.service.schemas import (
    CheckRequest,
    GroundRequest,
    PlanRequest,
    SolveRequest,
    ValidateRequest,
)
from gsr.service.settings import ServiceSettings

log = logging.getLogger("gsr.service")
_OBJECT = TypeAdapter(dict[str, Any])
INLINE_NODES = 64  # a request over a scene this small (and a short plan) is computed on the event loop
INLINE_STEPS = 32
ROUTES = (
    "/health",
    "/metrics",
    "/v1/domains",
    "/v1/check",
    "/v1/validate",
    "/v1/plan",
    "/v1/ground",
    "/v1/solve",
    "/v1/scene-graph/validate",
    "/v1/scenes",
    "/openapi.json",
    "/docs",
)


def _route_of(path: str) -> str:
    if path in ROUTES:
        return path
    if path.startswith("/v1/scenes/"):
        return "/v1/scenes/{scene_id}"
    return "other"


def _parse(body: bytes, model: type[BaseModel] | TypeAdapter) -> Any:
    """The body validated against ``model``: 400 for bad or too deeply nested JSON, 422 for bad fields."""
    try:
        if isinstance(model, TypeAdapter):
            return model.validate_json(body)
        return model.model_validate_json(body)
    except ValidationError as exc:
        errors = exc.errors(include_url=False, include_context=False, include_input=False)
        if any(e["type"] == "json_invalid" for e in errors):
            msg = errors[0]["msg"]
            if "recursion limit" in msg:
                raise ApiError(
                    400, "json_too_deep", "request body is nested too deeply", limit="json_depth"
                ) from None
            raise ApiError(400, "invalid_json", f"request body is not valid JSON: {msg}") from None
        fields = [
            {"field": ".".join(str(p) for p in e.get("loc", ())) or "body", "message": e.get("msg", "")}
            for e in errors
        ]
        first = fields[0]
        raise ApiError(
            422, "invalid_request", f"{first['field']}: {first['message']}", errors=fields
        ) from None


def _small(data: Any, steps: int = 0) -> bool:
    nodes = data.get("nodes") if isinstance(data, dict) else None
    return isinstance(nodes, list) and len(nodes) <= INLINE_NODES and steps <= INLINE_STEPS


def _preload() -> None:
    """Load what in-process requests use at startup rather than inside the first requests: the modules
    come with gsr.service.handlers (imported above), the built-in domain is read here."""
    with contextlib.suppress(GSRError):  # a missing domain is reported by the requests that name it
        builtin_domain("tabletop")


def create_app(settings: ServiceSettings | None = None) -> FastAPI:
    """The FastAPI application with keys and limits from ``settings`` (defaults: ServiceSettings())."""
    settings = settings or ServiceSettings()
    state_dir = settings.state_path
    metrics = Metrics(state_dir / "metrics")
    scenes = SceneStore(
        settings,
        state_dir / "scenes",
        on_lookup=lambda result: metrics.inc("gsr_scene_cache_total", result=result),
    )
    pool = IsolatedPool(settings, on_event=lambda why: metrics.inc("gsr_worker_restarts_total", reason=why))
    slots = asyncio.Semaphore(max(settings.max_concurrent, 0))

    @asynccontextmanager
    async def lifespan(_: FastAPI):
        warming = asyncio.create_task(pool.warm()) if settings.warm_workers else None
        _preload()
        gc.freeze()  # the long-lived startup objects leave the collector's generations: shorter pauses
        yield
        if warming is not None and not warming.done():
            warming.cancel()
        pool.close()
        metrics.write_snapshot()

    app = FastAPI(
        title="GSR reasoning API",
        version=__version__,
        description="Check steps, validate plans, plan and ground instructions over grounded scene graphs.",
        lifespan=lifespan,
    )
    app.state.settings, app.state.metrics, app.state.pool, app.state.scenes = settings, metrics, pool, scenes

    def scene_source(req: Any, parse_here: bool) -> Scene | dict[str, Any] | None:
        """The stored scene, or the inline graph checked for size: parsed (and cached by content)
        when it is computed here, else as data for the worker process to parse."""
        if getattr(req, "scene_id", None) is not None:
            if req.scene_graph is not None:
                raise ApiError(422, "invalid_request", "give scene_graph or scene_id, not both")
            return scenes.get(req.scene_id)
        if req.scene_graph is None:
            return None
        check_scene_size(req.scene_graph, settings)
        if parse_here and _small(req.scene_graph):
            return scenes.inline(req.scene_graph)
        return req.scene_graph

    def is_small(source: Any, steps: int = 0) -> bool:
        if isinstance(source, Scene):
            return len(source.graph.nodes) <= INLINE_NODES and steps <= INLINE_STEPS
        return source is None or _small(source, steps)

    async def in_thread(fn: Callable[..., Any], *args: Any) -> Any:
        """Bounded but not tiny work (a large scene): a worker thread, at most max_concurrent at once."""
        try:
            await asyncio.wait_for(slots.acquire(), timeout=settings.queue_timeout)
        except TimeoutError:
            err = ApiError(
                429,
                "busy",
                "all in-process slots are busy; retry later",
                limit="GSR_SERVICE_MAX_CONCURRENT",
                max=settings.max_concurrent,
                retry_after=1,
            )
            raise err from None
        try:
            return await run_in_threadpool(fn, *args)
        finally:
            slots.release()

    async def isolated(name: str, req: Any, source: Any) -> dict[str, Any]:
        timeout = getattr(req, "timeout", None)
        budget = min(timeout or settings.max_plan_seconds, settings.max_plan_seconds)
        return await pool.run(name, req, source, budget * 1.5 + 2.0)  # the planner stops itself first

    # ------------------------------------------------------------------ errors

    def _answer(request: Request, err: ApiError) -> JSONResponse:
        if err.status in (401, 413, 429) or "limit" in err.details:
            metrics.inc("gsr_rejections_total", reason=rejection_reason(err.kind, err.details))
        headers = {"Retry-After": str(err.details["retry_after"])} if "retry_after" in err.details else None
        body = error_body(
            err.kind, err.message, **err.details, request_id=request.scope["state"].get("request_id")
        )
        return JSONResponse(body, err.status, headers=headers)

    @app.exception_handler(Exception)
    async def any_error(request: Request, exc: Exception) -> JSONResponse:
        err = api_error_from(exc)
        if err is not None:
            return _answer(request, err)
        rid = request.scope.get("state", {}).get("request_id")
        log.error("internal error on %s", request.url.path, exc_info=exc, extra={"request_id": rid})
        return JSONResponse(
            error_body("internal_error", "the server failed on this request; see its log", request_id=rid),
            500,
        )

    for kind in (ApiError, GSRError, RecursionError, MemoryError):  # answered here, not re-raised
        app.add_exception_handler(kind, any_error)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        kind = {404: "not_found", 405: "method_not_allowed"}.get(exc.status_code, "http_error")
        return _answer(request, ApiError(exc.status_code, kind, str(exc.detail)))

    # ------------------------------------------------------------------ endpoints

    def body_of(model: type[BaseModel]) -> dict[str, Any]:
        ref = {"$ref": f"#/components/schemas/{model.__name__}"}
        return {"requestBody": {"required": True, "content": {"application/json": {"schema": ref}}}}

    @app.get("/health")
    async def health() -> JSONResponse:
        """Liveness (no API key needed)."""
        return JSONResponse({"status": "ok", "version": __version__, "time": time.time()})

    @app.get("/metrics", response_class=PlainTextResponse)
    async def metrics_endpoint() -> PlainTextResponse:
        """Prometheus text format: requests, latency histograms, rejections by reason, worker restarts."""
        text = await run_in_threadpool(metrics.render)
        return PlainTextResponse(text, media_type="text/plain; version=0.0.4; charset=utf-8")

    @app.get("/v1/domains")
    async def domains() -> list[dict[str, Any]]:
        """The built-in domains with their action signatures."""
        return await run_in_threadpool(list_domains)

    @app.post("/v1/check", openapi_extra=body_of(CheckRequest))
    async def check(request: Request) -> JSONResponse:
        """Check one step against a scene graph (inline or ``scene_id``): 200 with ``ok`` and the diagnosis."""
        req = _parse(await request.body(), CheckRequest)
        here = req.domain_pddl is None
        source = scene_source(req, here)
        if source is None:
            raise ApiError(422, "invalid_request", "give scene_graph or scene_id")
        if not here:  # user PDDL: its quantifiers can make one check unbounded
            return JSONResponse(await isolated("check", req, source))
        if is_small(source):
            return JSONResponse(run_handler("check", req, settings, source))
        return JSONResponse(await in_thread(run_handler, "check", req, settings, source))

    @app.post("/v1/validate", openapi_extra=body_of(ValidateRequest))
    async def validate(request: Request) -> JSONResponse:
        """Validate a plan: 200 with ``valid``, per-step diagnoses and unmet goal literals."""
        req = _parse(await request.body(), ValidateRequest)
        here = req.domain_pddl is None and req.problem_pddl is None
        source = scene_source(req, here)
        steps = check_plan_length(req, settings)
        if here and is_small(source, steps):
            return JSONResponse(run_handler("validate", req, settings, source))
        # user PDDL, or a long plan over a large scene: in a worker, within the time budget
        return JSONResponse(await isolated("validate", req, source))

    @app.post("/v1/plan", openapi_extra=body_of(PlanRequest))
    async def plan_endpoint(request: Request) -> JSONResponse:
        """Plan a PDDL problem or a scene graph + goal within the server's time budget."""
        req = _parse(await request.body(), PlanRequest)
        return JSONResponse(await isolated("plan", req, scene_source(req, parse_here=False)))

    @app.post("/v1/ground", openapi_extra=body_of(GroundRequest))
    async def ground_endpoint(request: Request) -> JSONResponse:
        """Ground an instruction to a goal formula (422 names unknown words or ambiguous objects)."""
        req = _parse(await request.body(), GroundRequest)
        check_instruction(req.instruction, settings)
        return JSONResponse(await isolated("ground", req, scene_source(req, parse_here=False)))

    @app.post("/v1/solve", openapi_extra=body_of(SolveRequest))
    async def solve(request: Request) -> JSONResponse:
        """Instruction -> goal -> plan, every step checked."""
        req = _parse(await request.body(), SolveRequest)
        check_instruction(req.instruction, settings)
        return JSONResponse(await isolated("solve", req, scene_source(req, parse_here=False)))

    @app.post("/v1/scene-graph/validate")
    async def scene_graph_validate(request: Request) -> dict[str, Any]:
        """Validate a scene graph (JSON or GSR-Bench message); 422 names the offending field."""
        data = _parse(await request.body(), _OBJECT)
        check_scene_size(data, settings, "body")
        if _small(data):
            return scene_summary(scenes.inline(data, "body"))
        return await in_thread(lambda: scene_summary(Scene.from_data(data, settings, "body")))

    @app.post("/v1/scenes", status_code=201)
    async def store_scene(request: Request) -> dict[str, Any]:
        """Store a scene graph; answer its ``scene_id`` for /v1/check and /v1/validate."""
        data = _parse(await request.body(), _OBJECT)
        check_scene_size(data, settings, "body")
        scene_id, scene = scenes.put(data) if _small(data) else await in_thread(scenes.put, data)
        return {"scene_id": scene_id, "nodes": len(scene.graph.nodes), "edges": len(scene.graph.edges)}

    @app.get("/v1/scenes/{scene_id}")
    async def get_scene(scene_id: str) -> dict[str, Any]:
        """A stored scene's node/edge counts and the atoms it entails (404 ``unknown_scene``)."""
        return {"scene_id": scene_id, **scene_summary(scenes.get(scene_id))}

    default_openapi = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            spec = default_openapi()  # caches itself in app.openapi_schema
            components = spec.setdefault("components", {}).setdefault("schemas", {})
            for model in (CheckRequest, ValidateRequest, PlanRequest, GroundRequest, SolveRequest):
                schema = model.model_json_schema(ref_template="#/components/schemas/{model}")
                components.update(schema.pop("$defs", {}))
                components[model.__name__] = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    app.add_middleware(ServiceMiddleware, settings=settings, metrics=metrics, route_of=_route_of)
    return app
