"""The episode runner: agents propose steps, the checker validates each, the goal is scored at the end.

The agent, executor and result types are the core's episode seams (:mod:`gsr.episode`). ``executor``
is the seam for physical execution: the default :class:`~gsr.symbolic_executor.SymbolicExecutor`
applies a step through :func:`gsr.check.check_step` (``GSRBenchExecutor`` adds GSR-Bench's rules for
its suites); a simulator executor (``skills``) implements the same
:class:`~gsr.episode.Executor` protocol and returns the observed state. Episodes run in-process, in
local worker processes (``backend="local"``, multiprocessing) or as Ray tasks (``backend="ray"``);
every episode's random choices derive from (seed, task id, trial), so all backends give the same
results for the same seed.
"""

from __future__ import annotations

import re
import time
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from gsr.benchmarks.agents import make_agent
from gsr.benchmarks.gsr_bench_executor import GSR_BENCH_SUITES, GSRBenchExecutor
from gsr.benchmarks.scoring import any_goal, score_task
from gsr.skills.perceived_executor import RunnerSimExecutor

from gsr.diagnosis import Diagnosis
from gsr.episode import AgentFailure, EpisodeResult, Executor
from gsr.errors import GSRError
from gsr.io import write_bytes_atomic
from gsr.pddl.model import Domain
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.resources import load_builtin_domain
from gsr.semantics import holds
from gsr.symbolic_executor import SymbolicExecutor
from gsr.task_spec import TaskSpec, task_from_dict


def episode_seed(seed: int, task_id: str, trial: int) -> int:
    """The deterministic per-episode seed."""
    return zlib.crc32(f"{seed}:{task_id}:{trial}".encode()) & 0x7FFFFFFF


def run_episode(
    task: TaskSpec,
    agent: Any,
    domain: Domain,
    seed: int = 0,
    trial: int = 0,
    max_steps: int = 200,
    retries: int = 0,
    executor: Executor | None = None,
) -> EpisodeResult:
    """Run one episode: ask the agent for steps until done, a rejected step, or the step limit."""
    if executor is None:
        executor = GSRBenchExecutor() if task.suite in GSR_BENCH_SUITES else SymbolicExecutor()
    eseed = episode_seed(seed, task.id, trial)
    start = time.perf_counter()
    state = executor.reset(task, domain)
    proposed = valid = 0
    plan: list[str] = []
    failure: dict[str, Any] | None = None
    said_done = False
    outcome_hint, reason = "", ""
    try:
        # an executor that perceives shows the agent its perceived initial graph, not the task's
        shown = getattr(executor, "agent_task", None)
        agent.reset(shown(task) if shown is not None else task, domain, eseed)
        feedback: Diagnosis | None = None
        tries = 0
        # how often each step failed in this episode: a step that fails again after the steps between
        # succeeded (pick, place fails, pick again, place fails ...) is not retried without end
        failed: dict[str, int] = {}
        while True:
            if valid >= max_steps:
                outcome_hint, reason = "planning_error", f"step limit {max_steps} reached"
                break
            step = agent.act(executor.graph(), task.instruction, feedback)
            if step is None:
                said_done = True
                break
            proposed += 1
            diagnosis = executor.execute(step)
            if diagnosis.ok:
                valid += 1
                plan.append(str(step))
                state = diagnosis.next_state or state
                feedback, tries = diagnosis, 0
                continue
            tries += 1
            failed[str(step)] = failed.get(str(step), 0) + 1
            if tries > retries or failed[str(step)] > retries:
                failure = diagnosis.to_dict()
                outcome_hint, reason = (
                    "planning_error",
                    f"step {valid + 1} rejected: {diagnosis.message}",
                )
                break
            feedback = diagnosis
    except AgentFailure as exc:
        outcome_hint, reason = "planning_error", f"agent failed: {exc}"
    except GSRError as exc:
        outcome_hint, reason = "planning_error", f"error: {exc}"
    # answers a reasoner rejected internally (before returning a checked step) are proposals too
    proposed += int(getattr(agent, "rejected_proposals", 0) or 0)
    # a physical executor is judged on the world's ground truth, not on what its agent observed
    truth = getattr(executor, "truth_state", None)
    score = score_task(domain, task, truth() if truth is not None else state)
    perceived = None
    if getattr(executor, "perceive", False):
        perceived = score_task(domain, task, executor.belief_state()).success  # type: ignore[attr-defined]
    if score.success:
        outcome = "true_success"
        reason = f"goal reached, although {reason}" if reason else "goal reached"
    elif outcome_hint:
        outcome = outcome_hint
    else:
        believed = getattr(agent, "believed_goal", None)
        if said_done and believed is not None and holds(domain, believed, state):
            outcome, reason = "goal_error", "the agent reached its own goal, which is not the task's"
        else:
            outcome = "false_positive"
            reason = f"agent declared done but only {score.satisfied}/{score.total} goal relations hold"
    return EpisodeResult(
        id=task.id,
        suite=task.suite,
        category=task.category,
        level=task.level,
        trial=trial,
        seed=eseed,
        success=score.success,
        score=score.score,
        recall=score.recall,
        steps=valid,
        proposed=proposed,
        valid=valid,
        outcome=outcome,
        reason=reason,
        time=round(time.perf_counter() - start, 4),
        best_alternative=score.best,
        failure=failure,
        plan=plan,
        perceived_success=perceived,
    )


@dataclass(frozen=True)
class RunConfig:
    """What to run: agent spec and options, limits, seed (picklable: it travels to workers)."""

    agent: str = "planner"
    agent_options: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    max_steps: int = 200
    retries: int = 0
    reference: str | None = None  # a planner name: also record its plan length ("plan length vs optimal")
    physical: bool = False  # execute steps in the PyBullet world (gsr.skills.SimExecutor), closed loop
    perceive: bool = False  # physical: the agent observes perceived graphs (cameras), not ground truth
    frames_dir: str | None = None  # physical: save a few RGB frames per episode here (PNG)
    frames: int = 3  # how many: first, evenly spaced, last
    oracle_masks: bool = False  # perceive: from the simulator's labelled masks instead of the detector


def episode_job(task_data: dict[str, Any], trial: int, config: RunConfig) -> dict[str, Any]:
    """Worker entry: rebuild the task and agent, run one episode, return its record."""
    task = task_from_dict(task_data, source=f"task {task_data.get('id')}")
    agent = make_agent(config.agent, config.agent_options)
    domain = load_builtin_domain("tabletop")
    executor = None
    if config.physical:  # the simulator executor implements the Executor seam (skills, 'sim' extra)
        frames = config.frames if config.frames_dir else 0
        executor = RunnerSimExecutor(
            episode_seed(config.seed, task.id, trial),
            config.perceive,
            frames,
            oracle_masks=config.oracle_masks,
        )
    try:
        result = run_episode(
            task, agent, domain, config.seed, trial, config.max_steps, config.retries, executor
        )
        if executor is not None and config.frames_dir:
            result.frames = save_frames(executor.frames, config.frames_dir, task.id, trial)
    finally:
        if executor is not None:
            executor.close()
    if config.reference:
        result.reference_steps = reference_length(task, domain, config.reference)
    return result.to_dict()


def save_frames(frames: list[Any], folder: str, task_id: str, trial: int) -> list[str]:
    """Write an episode's RGB frames as PNGs (atomically) into ``folder``; paths relative to its parent."""
    from pathlib import Path

    out = Path(folder)
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", task_id)[:120]
    names = []
    for k, rgb in enumerate(frames):
        name = f"{stem}-t{trial}-{k}.png"
        write_bytes_atomic(out / name, png_bytes(rgb))
        names.append(f"{out.name}/{name}")
    return names


def png_bytes(rgb: Any) -> bytes:
    """An RGB array (HxWx3 uint8) encoded as PNG."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG")
    return buf.getvalue()


def reference_length(
    task: TaskSpec, domain: Domain, planner: str = "lazy-ff", timeout: float = 120.0
) -> int | None:
    """Length of the reference plan (optimal with an A* planner, best-found with lazy-ff); None if none."""
    result = plan_api.plan_graph(domain, task.initial, any_goal(task), planner=planner, timeout=timeout)
    return len(result.plan) if result.solved and result.plan is not None else None


def _jobs(tasks: list[TaskSpec], trials: int) -> list[tuple[dict[str, Any], int]]:
    return [(t.model_dump(mode="json"), k) for t in tasks for k in range(trials)]


def _from_dict(d: dict[str, Any]) -> EpisodeResult:
    d = {k: v for k, v in d.items() if k != "executability"}
    return EpisodeResult(**d)


JobFn = Callable[[dict[str, Any], int, Any], dict[str, Any]]


def _iter_local(
    fn: JobFn, jobs: list[tuple[dict[str, Any], int]], config: Any, workers: int
) -> Iterator[dict[str, Any]]:
    if workers <= 1:
        for data, trial in jobs:
            yield fn(data, trial, config)
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    ctx = mp.get_context("spawn")  # no forked copies of a half-initialised parent (threads, locks)
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        yield from pool.map(fn, *zip(*jobs, strict=True), [config] * len(jobs))


def _iter_ray(
    fn: JobFn, jobs: list[tuple[dict[str, Any], int]], config: Any, address: str | None
) -> Iterator[dict[str, Any]]:
    try:
        import ray
    except ImportError:
        raise GSRError("--backend ray needs Ray: pip install 'gsr[dist]'") from None
    if not ray.is_initialized():
        ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
    remote = ray.remote(fn)
    refs = [remote.remote(data, trial, config) for data, trial in jobs]
    for ref in refs:  # in submission order: results line up with the local backend
        yield ray.get(ref)


def run_jobs(
    fn: JobFn,
    jobs: list[tuple[dict[str, Any], int]],
    config: Any,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    progress: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``fn(payload, trial, config)`` for every job on a backend; records in job order.

    ``fn`` must be a module-level function and payloads/config picklable: they travel to worker
    processes or Ray tasks. This is the pool both PDDL-step suites and episode suites run on.
    """
    if backend == "local":
        stream = _iter_local(fn, jobs, config, workers)
    elif backend == "ray":
        stream = _iter_ray(fn, jobs, config, address)
    else:
        raise GSRError(f"unknown backend {backend!r}; choose local or ray")
    out = []
    for d in stream:
        out.append(d)
        if progress is not None:
            progress(d)
    return out


def run_tasks(
    tasks: Iterable[TaskSpec],
    config: RunConfig | None = None,
    trials: int = 1,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    progress: Callable[[EpisodeResult], None] | None = None,
) -> list[EpisodeResult]:
    """Run every task ``trials`` times; results come back in task order whatever the backend."""
    config = config or RunConfig()
    if config.perceive and not config.physical:
        raise GSRError("--perceive needs --physical (perception observes the simulated world)")
    make_agent(config.agent, config.agent_options)  # fail fast on a bad agent, before any worker starts
    jobs = _jobs(list(tasks), trials)
    out: list[EpisodeResult] = []

    def collect(d: dict[str, Any]) -> None:
        out.append(_from_dict(d))
        if progress is not None:
            progress(out[-1])

    run_jobs(episode_job, jobs, config, workers, backend, address, collect)
    return out
