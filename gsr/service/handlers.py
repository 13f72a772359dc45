"""What each endpoint computes, as plain functions of a request model (no HTTP here).

They run in the server process (check, validate and scenes over a built-in domain: bounded by the size
limits) or in an isolated worker process (planning, solving, grounding, user PDDL: bounded by a time
budget that kills the worker), so they must be importable and picklable: ``gsr.service.pool`` calls
them by name.
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from typing import Any

from gsr.check import check_step
from gsr.diagnosis import typed_text
from gsr.errors import GSRError
from gsr.facts import facts, graph_objects
from gsr.io import scene_from_data
from gsr.language import ground
from gsr.pddl.model import Problem
from gsr.pddl.parser import parse_atom, parse_domain, parse_formula, parse_problem
from gsr.pddl.writer import write_formula
from gsr.plan import PLANNERS, plan
from gsr.plan_format import parse_plan
from gsr.reason import MODES, solve
from gsr.resources import data_dir, load_builtin_domain
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
from gsr.state import State
from gsr.step import Plan, Step
from gsr.validate import validate_plan


class ApiError(Exception):
    """An error answered with ``status`` and a structured body ``{"error": {"type", "message", ...}}``."""

    def __init__(self, status: int, kind: str, message: str, **details: Any) -> None:
        super().__init__(message)
        self.status, self.kind, self.message, self.details = status, kind, message, details

    def body(self) -> dict[str, Any]:
        return error_body(self.kind, self.message, **self.details)


def error_body(kind: str, message: str, **details: Any) -> dict[str, Any]:
    return {"error": {"type": kind, "message": message, **details}}


def limit_error(status: int, kind: str, setting: str, limit: float, message: str) -> ApiError:
    """An error for a request over a server limit; it names the variable that sets the limit."""
    return ApiError(status, kind, message, limit=f"GSR_SERVICE_{setting.upper()}", max=limit)


def api_error_from(exc: BaseException) -> ApiError | None:
    """The client-facing error for an exception a handler raised (None: a server bug)."""
    if isinstance(exc, ApiError):
        return exc
    if isinstance(exc, GSRError):
        extra: dict[str, Any] = {}
        for attr in ("unknown_words", "candidates"):  # grounding errors carry these
            value = getattr(exc, attr, None)
            if value:
                extra[attr] = value if isinstance(value, list | dict | str) else list(value)
        return ApiError(422, type(exc).__name__, str(exc), **extra)
    if isinstance(exc, RecursionError):
        return ApiError(422, "too_deep", "the input is nested too deeply to process")
    if isinstance(exc, MemoryError):
        return ApiError(
            422,
            "memory_limit",
            "the request needs more memory than a worker may use",
            limit="GSR_SERVICE_WORKER_MEMORY_MB",
        )
    return None


# ------------------------------------------------------------------ inputs


@lru_cache(maxsize=32)
def _parse_domain_text(digest: str, text: str):  # digest keys the cache without hashing long text twice

    return parse_domain(text, source="domain_pddl")


@lru_cache(maxsize=16)
def builtin_domain(name: str):  # per process: a server reads its domain files once (restart to reload)

    return load_builtin_domain(name)


def domain_of(ref: DomainRef):
    """The request's domain: parsed PDDL text (cached by digest) or a built-in domain (cached)."""
    if ref.domain_pddl is not None:
        return _parse_domain_text(hashlib.sha1(ref.domain_pddl.encode()).hexdigest(), ref.domain_pddl)
    return builtin_domain(ref.domain)


def check_scene_size(data: Any, settings: ServiceSettings, field: str = "scene_graph") -> None:
    """422 naming the limit when a scene graph has more nodes or edges than the server accepts."""
    if not isinstance(data, dict):
        return
    for key, setting in (("nodes", "max_nodes"), ("edges", "max_edges")):
        items = data.get(key)
        limit = getattr(settings, setting)
        if isinstance(items, list | dict) and len(items) > limit:
            raise limit_error(
                422,
                "scene_too_large",
                setting,
                limit,
                f"{field} has {len(items)} {key}; this server accepts at most {limit}",
            )


class Scene:
    """A parsed scene graph with the states it entails per built-in domain, computed once.

    A stored scene (POST /v1/scenes) keeps one of these in memory, so checking many steps against it
    parses nothing again.
    """

    __slots__ = ("_derived", "_facts", "graph")

    def __init__(self, graph) -> None:
        self.graph = graph
        self._derived: dict[str, Any] = {}  # per built-in domain: (objects, facts) and the State
        self._facts: frozenset | None = None

    def __getstate__(self):  # to a worker process: the graph only (the caches hold unpicklable indexes)
        return self.graph

    def __setstate__(self, graph) -> None:
        self.__init__(graph)

    @property
    def facts(self) -> frozenset:
        """The atoms the graph entails (domain-independent; computed once)."""
        if self._facts is None:
            self._facts = frozenset(facts(self.graph))
        return self._facts

    @classmethod
    def from_data(cls, data: dict[str, Any], settings: ServiceSettings, field: str = "scene_graph") -> Scene:
        check_scene_size(data, settings, field)
        return cls(scene_from_data(data, source=field))

    def objects_and_facts(self, domain, ref: DomainRef) -> tuple[dict[str, str], frozenset]:
        """(objects, true atoms) of the graph in ``domain``; cached for built-in domains."""
        key = None if ref.domain_pddl is not None else ref.domain
        cached = self._derived.get(key) if key is not None else None
        if cached is None:
            cached = (graph_objects(self.graph, domain), self.facts)
            if key is not None:
                self._derived[key] = cached
        return cached

    def state(self, domain, ref: DomainRef):
        """The symbolic state; for built-in domains the same State object every time, so the checker's
        per-state indexes are built once per scene."""
        key = None if ref.domain_pddl is not None else "state:" + ref.domain
        state = self._derived.get(key) if key is not None else None
        if state is None:
            objects, atoms = self.objects_and_facts(domain, ref)
            state = State(atoms, {**domain.constants, **objects})
            if key is not None:
                self._derived[key] = state
        return state


def _step(value: str | StepIn, where: str = "step"):

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


def _task(req: TaskIn, scene: Scene | None):
    """(domain, problem) from a PDDL problem or from a scene graph + goal."""
    domain = domain_of(req)
    if req.problem_pddl is not None:
        return domain, parse_problem(req.problem_pddl, source="problem_pddl", domain=domain)
    if scene is None or req.goal is None:
        raise ApiError(
            422, "invalid_request", "give either problem_pddl, or scene_graph (or scene_id) and goal"
        )
    goal = parse_formula(req.goal, source="goal")
    objects, atoms = scene.objects_and_facts(domain, req)
    return domain, Problem(name="task", domain_name=domain.name, objects=dict(objects), init=atoms, goal=goal)


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


def check_plan_length(req: ValidateRequest, settings: ServiceSettings) -> int:
    """The number of steps in the request's plan; 422 naming the limit when there are too many."""
    n = len(req.plan) if isinstance(req.plan, list) else sum(1 for ln in req.plan.splitlines() if "(" in ln)
    if n > settings.max_steps:
        raise limit_error(
            422,
            "too_many_steps",
            "max_steps",
            settings.max_steps,
            f"plan has {n} steps; the limit is {settings.max_steps}",
        )
    return n


def check_instruction(text: str, settings: ServiceSettings) -> None:
    if len(text) > settings.max_instruction_chars:
        raise limit_error(
            422,
            "instruction_too_long",
            "max_instruction_chars",
            settings.max_instruction_chars,
            f"instruction has {len(text)} characters; this server accepts at most {settings.max_instruction_chars}",
        )


# ------------------------------------------------------------------ handlers


def handle_check(req: CheckRequest, settings: ServiceSettings, scene: Scene) -> dict[str, Any]:
    """Check one step against a scene graph."""
    domain = domain_of(req)
    return check_step(domain, scene.state(domain, req), _step(req.step)).to_dict()


def handle_validate(req: ValidateRequest, settings: ServiceSettings, scene: Scene | None) -> dict[str, Any]:
    """Validate a plan against a task."""
    check_plan_length(req, settings)
    if isinstance(req.plan, str):
        plan = parse_plan(req.plan, source="plan")
    else:
        plan = Plan(tuple(_step(s, where=f"plan[{i}]") for i, s in enumerate(req.plan)))
    if req.problem_pddl is None and scene is not None and req.goal is not None:
        domain = domain_of(req)  # from the scene's cached state: no problem to build
        goal = parse_formula(req.goal, source="goal")
        return validate_plan(domain, scene.state(domain, req), plan, goal=goal).to_dict()
    domain, problem = _task(req, scene)
    return validate_plan(domain, problem, plan).to_dict()


def handle_plan(req: PlanRequest, settings: ServiceSettings, scene: Scene | None) -> dict[str, Any]:
    """Plan a task within the server's time budget."""
    if req.planner not in PLANNERS or req.planner == "fd":
        offered = ", ".join(p for p in PLANNERS if p != "fd")
        raise ApiError(422, "unknown_planner", f"unknown planner {req.planner!r}; choose one of {offered}")
    timeout = min(req.timeout or settings.max_plan_seconds, settings.max_plan_seconds)
    domain, problem = _task(req, scene)
    return _plan_result_dict(plan(domain, problem, planner=req.planner, timeout=timeout))


def handle_ground(req: GroundRequest, settings: ServiceSettings, scene: Scene) -> dict[str, Any]:
    """Ground an instruction into a goal formula over the graph."""
    check_instruction(req.instruction, settings)
    goal = ground(req.instruction, scene.graph)
    return {"goal": write_formula(goal.formula), "instruction": req.instruction}


def handle_solve(req: SolveRequest, settings: ServiceSettings, scene: Scene) -> dict[str, Any]:
    """Instruction -> goal -> checked steps, through the reasoner loop with a server-approved backend."""
    if req.backend not in settings.backends:
        offered = ", ".join(settings.backends)
        raise ApiError(
            422, "unknown_backend", f"backend {req.backend!r} is not offered here (offered: {offered})"
        )
    if req.mode not in MODES:
        raise ApiError(422, "unknown_mode", f"unknown mode {req.mode!r}; choose one of {', '.join(MODES)}")
    check_instruction(req.instruction, settings)
    timeout = min(req.timeout or settings.max_plan_seconds, settings.max_plan_seconds)
    result = solve(scene.graph, req.instruction, backend=req.backend, mode=req.mode, planner_timeout=timeout)
    return result.to_dict()


def scene_summary(scene: Scene) -> dict[str, Any]:
    """Node/edge counts and the atoms a graph entails."""
    return {
        "valid": True,
        "nodes": len(scene.graph.nodes),
        "edges": len(scene.graph.edges),
        "facts": sorted(map(str, scene.facts)),
    }


def list_domains() -> list[dict[str, Any]]:
    """The built-in domains with their action signatures."""
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


def run_handler(name: str, req: Any, settings: ServiceSettings, source: Scene | dict[str, Any] | None):
    """Handler ``name`` over a parsed scene, or over scene-graph data parsed here (where it runs)."""
    scene = source if isinstance(source, Scene) or source is None else Scene.from_data(source, settings)
    return HANDLERS[name](req, settings, scene)


HANDLERS = {
    "check": handle_check,
    "validate": handle_validate,
    "plan": handle_plan,
    "ground": handle_ground,
    "solve": handle_solve,
}
