"""Logic behind ``gsr bench ...`` (gsr/cli.py declares the options and imports this lazily)."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any

from gsr.benchmarks.agents import BUILTIN
from gsr.benchmarks.report import results_document, write_reports
from gsr.benchmarks.runner import RunConfig, run_jobs, run_tasks
from gsr.benchmarks.suites import SUITES, get_suite

from gsr.episode import EpisodeOptions
from gsr.errors import GSRError
from gsr.io import write_text_atomic
from gsr.task_spec import task_json


def list_text() -> str:
    """The suites and agents, one per line."""
    lines = ["suites:"]
    lines += [f"  {s.name:<14} {s.description}" for s in SUITES.values()]
    lines.append("agents (TaskSpec suites):")
    lines += [f"  {a}" for a in BUILTIN]
    lines.append("  package.module:factory  (your own agent; options with --agent-opt key=value)")
    for s in SUITES.values():
        hosted = s.episode_suite()
        if hosted is not None:
            lines.append(f"agents ({s.name}):")
            lines += [f"  {a:<14} {d}" for a, d in hosted.agents.items()]
    return "\n".join(lines)


def parse_options(pairs: list[str]) -> dict[str, Any]:
    """``key=value`` pairs; values parsed as JSON when they can be (numbers, booleans), else strings."""
    out: dict[str, Any] = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise GSRError(f"--agent-opt {pair!r}: expected key=value")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


def load_suite_tasks(suite: str, source: str | None, tasks: str | None, seed: int, limit: int | None) -> list:
    """The tasks of a suite (``--tasks`` overrides the source), cut to ``limit``."""
    s = get_suite("tasks" if tasks else suite)
    out = s.tasks(tasks or source, seed)
    if limit is not None:
        if limit < 1:
            raise GSRError("--limit must be at least 1")
        out = out[:limit]
    return out


class _Progress:
    """A one-line progress display on a terminal's stderr (silent when stderr is not a terminal)."""

    def __init__(self, total: int) -> None:
        self.total, self.done, self.ok = total, 0, 0
        self.tty = sys.stderr.isatty()
        self.start = time.perf_counter()

    def __call__(self, result: Any) -> None:
        self.done += 1
        self.ok += bool(result["success"] if isinstance(result, dict) else result.success)
        if self.tty:
            width = 30
            filled = int(width * self.done / max(self.total, 1))
            sys.stderr.write(
                f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} "
                f"success {self.ok}/{self.done} {time.perf_counter() - self.start:6.1f}s"
            )
            sys.stderr.flush()

    def close(self) -> None:
        if self.tty:
            sys.stderr.write("\n")


def run(
    suite: str,
    *,
    source: str | None = None,
    tasks: str | None = None,
    agent: str | None = None,
    agent_options: list[str] | None = None,
    trials: int = 1,
    seed: int = 0,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    limit: int | None = None,
    max_steps: int = 200,
    retries: int = 0,
    reference: str | None = None,
    out: str | None = None,
    split: str | None = None,
    physical: bool = False,
    perceive: bool = False,
    oracle_masks: bool = False,
) -> dict[str, Any]:
    """Run a suite and write the reports; the results document."""
    if trials < 1 or workers < 1 or max_steps < 1 or retries < 0:
        raise GSRError("--trials, --workers and --max-steps must be at least 1, --retries at least 0")
    hosted = get_suite(suite).episode_suite() if suite in SUITES else None
    if hosted is not None:
        unused = [
            name
            for name, given in (
                ("--agent-opt", bool(agent_options)),
                ("--max-steps", max_steps != 200),
                ("--retries", retries != 0),
                ("--reference", reference is not None),
                ("--physical", physical),
                ("--perceive", perceive),
                ("--oracle-masks", oracle_masks),
            )
            if given
        ]
        if unused:
            raise GSRError(f"suite {suite} does not take {', '.join(unused)}")
        options = EpisodeOptions(agent, seed, trials, limit, source, tasks, split)
        return run_episode_suite(hosted, options, workers, backend, address, out)
    if split is not None:
        raise GSRError(f"--split applies to suites with splits (delivery), not {suite}")
    agent = agent or "planner"
    task_list = load_suite_tasks(suite, source, tasks, seed, limit)
    if perceive and not physical:
        raise GSRError("--perceive needs --physical (perception observes the simulated world)")
    if oracle_masks and not perceive:
        raise GSRError("--oracle-masks needs --perceive (it chooses where perception's masks come from)")
    frames_dir = str(Path(out) / "frames") if out and physical else None  # a few RGB frames per episode
    config = RunConfig(
        agent,
        parse_options(agent_options or []),
        seed,
        max_steps,
        retries,
        reference,
        physical,
        perceive=perceive,
        frames_dir=frames_dir,
        oracle_masks=oracle_masks,
    )
    progress = _Progress(len(task_list) * trials)
    try:
        results = run_tasks(task_list, config, trials, workers, backend, address, progress)
    finally:
        progress.close()
    doc = results_document(
        results,
        suite="tasks" if tasks else suite,
        agent=agent,
        seed=seed,
        trials=trials,
        backend=backend,
        workers=workers,
        max_steps=max_steps,
        retries=retries,
        physical=physical,
        perceive=perceive,
    )
    if out:
        write_reports(out, doc)
    return doc


def run_episode_suite(
    hosted: Any, options: Any, workers: int, backend: str, address: str | None, out: str | None
) -> dict[str, Any]:
    """Run an episode suite (``gsr.episode.EpisodeSuite``) on the runner's pool; write its reports."""
    payloads, config = hosted.prepare(options)
    jobs = [(p, k) for p in payloads for k in range(options.trials)]
    progress = _Progress(len(jobs))
    try:
        records = run_jobs(hosted.job(), jobs, config, workers, backend, address, progress)
    finally:
        progress.close()
    doc = hosted.document(records, config, trials=options.trials, backend=backend, workers=workers)
    if out:
        write_reports(out, doc, hosted.markdown(doc))
    return doc


def summary_text(doc: dict[str, Any]) -> str:
    """A few lines for the terminal: overall and per-category success."""
    hosted = SUITES[doc["suite"]].episode_suite() if doc["suite"] in SUITES else None
    if hosted is not None:
        return hosted.summary_text(doc)
    m = doc["metrics"]
    lines = [
        f"{doc['suite']} / {doc['agent']}: success {m.get('success_rate', 0):.1%} "
        f"({m.get('episodes', 0)} episodes), score {m.get('score', 0):.3f}, "
        f"executability {m.get('executability', 0):.3f}, mean steps {m.get('mean_steps')}",
    ]
    for name, c in doc["by_cell"].items():
        lines.append(f"  {name:<48} {c['success_rate']:>7.1%}  steps {c['mean_steps']}")
    return "\n".join(lines)


def export(suite: str, out: str, source: str | None = None, seed: int = 0) -> int:
    """Write every task of a suite as ``OUT/<id>.json`` (atomically); the number written."""
    task_list = load_suite_tasks(suite, source, None, seed, None)
    folder = Path(out)
    for t in task_list:
        write_text_atomic(folder / f"{t.id}.json", task_json(t) + "\n")
    return len(task_list)
