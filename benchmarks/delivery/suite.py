"""``gsr bench run delivery``: the delivery benchmark as an episode suite of the benchmark runner.

Delivery episodes are not PDDL-step tasks, so the suite implements ``gsr.episode.EpisodeSuite``:
it prepares one payload per task, the runner's pool (local processes or Ray, results in task order)
runs :func:`delivery_job` on each, and the records become the PRS-style metrics (Task SR, parsing,
manipulation and human-search SR, mean time) through the same code as ``gsr delivery run``
(:func:`gsr.benchmarks.delivery.run.play`, :func:`gsr.benchmarks.delivery.metrics.summarize`).

Seeds: with ``--seed 0`` (the default) trial 0 replays each task's own day (its ``world_seed``), which
gives the published figures; any other seed or trial re-draws the day (people's drift and errands,
grasp luck) from the runner's episode seed ``crc32(seed:id:trial)``, keeping instruction and start.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from gsr.benchmarks.delivery.agent import AgentTrace, BaselineAgent
from gsr.benchmarks.delivery.building.model import Building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.metrics import (
    EpisodeResult,
    Summary,
    breakdown_by,
    breakdown_table,
    facets,
    summarize,
    summary_table,
)
from gsr.benchmarks.delivery.run import AGENTS, checked_building, make_agent, play
from gsr.benchmarks.delivery.tasks import SPLITS, DeliveryTask, generate_tasks, load_tasks
from gsr.benchmarks.runner import episode_seed

from gsr.episode import EpisodeOptions
from gsr.errors import GSRError

OUTCOMES = (
    "success",
    "not_understood",
    "object_not_found",
    "not_grasped",
    "person_not_found",
    "not_delivered",
)
_FLAGS = ("parse_correct", "object_found", "grasped", "person_within_5m", "person_within_3m", "timed_out")


@dataclass(frozen=True)
class DeliveryJobConfig:
    """What every episode job needs besides its task (picklable: it travels to workers)."""

    building: str | None  # a building JSON path; None = the shipped building
    agent: str
    seed: int
    split: str


@lru_cache(maxsize=4)
def _world(building: str | None) -> tuple[Building, BuildingMap]:
    """The building and its map, loaded once per process (A* paths cached across episodes)."""
    b = checked_building(Path(building) if building else None)
    return b, BuildingMap(b)


@lru_cache(maxsize=8)
def _agent(building: str | None, agent: str) -> BaselineAgent:
    """The agent, built once per process (it starts every episode with fresh knowledge)."""
    b, bmap = _world(building)
    return make_agent(b, bmap, agent)


def outcome(result: EpisodeResult, trace: AgentTrace) -> str:
    """The stage an episode ended at (one of :data:`OUTCOMES`)."""
    if result.success:
        return "success"
    if trace.parsed is None or trace.person is None:
        return "not_understood"
    if not result.object_found:
        return "object_not_found"
    if not result.grasped:
        return "not_grasped"
    return "not_delivered" if result.person_within_3m else "person_not_found"


def delivery_job(payload: dict[str, Any], trial: int, config: DeliveryJobConfig) -> dict[str, Any]:
    """Worker entry: run one delivery episode and return its results.json row."""
    task = DeliveryTask.model_validate(payload["task"])
    eseed = episode_seed(config.seed, task.id, trial)
    if (config.seed, trial) != (0, 0):
        task = task.model_copy(update={"world_seed": eseed})
    building, bmap = _world(config.building)
    start = time.perf_counter()
    result, trace = play(building, bmap, _agent(config.building, config.agent), task)
    wall = time.perf_counter() - start
    kind = outcome(result, trace)
    timed = " (timed out)" if result.timed_out else ""
    reason = f"delivered in {result.time:.1f} s" if result.success else f"{kind}{timed}: {result.note}"
    f = payload["facets"]
    return {
        "id": task.id,
        "suite": "delivery",
        "category": f["object described by"],
        "level": f["recipient referred to by"],
        "trial": trial,
        "seed": eseed,
        "world_seed": task.world_seed,
        "success": result.success,
        # partial credit: the mean of the PRS partial scores and success (1.0 exactly on success)
        "score": round(
            (result.object_found + result.grasped + result.person_within_3m + result.success) / 4, 4
        ),
        "steps": result.actions,
        "outcome": kind,
        "reason": reason.rstrip(": "),
        **{k: getattr(result, k) for k in _FLAGS},
        "time": result.time,  # simulated seconds
        "metres": result.metres,
        "actions": result.actions,
        "note": result.note,
        "wall": round(wall, 5),  # CPU-side seconds of this episode
        "facets": f,
    }


def _result(row: dict[str, Any]) -> EpisodeResult:
    """The delivery EpisodeResult of a results.json row."""
    fields = {k: row[k] for k in EpisodeResult.model_fields if k != "task"}
    return EpisodeResult(task=row["id"], **fields)


def _group(rows: list[dict[str, Any]]) -> dict[str, Any]:
    n = len(rows)
    return {
        "episodes": n,
        "success_rate": round(sum(r["success"] for r in rows) / n, 4),
        "task_sr": round(100.0 * sum(r["success"] for r in rows) / n, 1),
        "manipulation_sr": round(100.0 * sum(r["grasped"] for r in rows) / n, 1),
        "human_search_sr": round(100.0 * sum(r["person_within_3m"] for r in rows) / n, 1),
        "mean_time": round(sum(r["time"] for r in rows) / n, 1),
    }


def _grouped(rows: list[dict[str, Any]], key: Any) -> dict[str, dict[str, Any]]:
    groups: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(key(r), []).append(r)
    return {k: _group(v) for k, v in sorted(groups.items(), key=lambda kv: -len(kv[1]))}


class DeliverySuite:
    """The ``delivery`` suite: tasks of a split (or a JSON Lines file) on a building, PRS metrics."""

    name = "delivery"
    agents = AGENTS
    default_agent = "baseline"

    def prepare(self, options: EpisodeOptions) -> tuple[list[dict[str, Any]], DeliveryJobConfig]:
        """Check agent, split and building; one payload per task and the job config."""
        agent = options.agent or self.default_agent
        if agent not in AGENTS:
            raise GSRError(f"suite delivery: unknown agent {agent!r}; choose one of {', '.join(AGENTS)}")
        if options.tasks and options.split:
            raise GSRError("suite delivery: pass --split or --tasks, not both")
        split = options.split or "test"
        if split not in SPLITS:
            raise GSRError(f"suite delivery: unknown split {split!r}; choose one of {', '.join(SPLITS)}")
        if options.limit is not None and options.limit < 1:
            raise GSRError("--limit must be at least 1")
        source = str(Path(options.source).resolve()) if options.source else None
        building, _ = _world(source)
        if options.tasks:
            tasks = load_tasks(options.tasks)[: options.limit]
            if not tasks:
                raise GSRError(f"{options.tasks}: no tasks")
            _check_tasks(tasks, building, options.tasks)
            split = Path(options.tasks).stem
        else:
            tasks = generate_tasks(building, split, options.limit)
        payloads = [{"id": t.id, "task": t.model_dump(mode="json"), "facets": facets(t)} for t in tasks]
        return payloads, DeliveryJobConfig(source, agent, options.seed, split)

    def job(self) -> Any:
        """:func:`delivery_job`."""
        return delivery_job

    def document(
        self, records: list[dict[str, Any]], config: DeliveryJobConfig, **meta: Any
    ) -> dict[str, Any]:
        """results.json: the PRS summary (as ``gsr delivery run``), groups, breakdown and every episode."""
        if not records:
            raise GSRError("suite delivery: no episodes to summarize")
        results = [_result(r) for r in records]
        summary = summarize(config.split, results, sum(r["wall"] for r in records))
        metrics = {
            **summary.model_dump(),
            "success_rate": round(sum(r.success for r in results) / len(results), 4),
            "score": round(statistics.fmean(r["score"] for r in records), 4),
            "outcomes": {o: sum(r["outcome"] == o for r in records) for o in OUTCOMES},
        }
        return {
            "suite": self.name,
            "agent": config.agent,
            "split": config.split,
            "building": config.building or "shipped (data/buildings/three_floor.json)",
            "seed": config.seed,
            **meta,
            "success_rate": metrics["success_rate"],
            "metrics": metrics,
            "by_category": _grouped(records, lambda r: r["category"]),
            "by_level": _grouped(records, lambda r: r["level"]),
            "by_cell": _grouped(records, lambda r: f"{r['category']} / {r['level']}"),
            "breakdown": breakdown_by([r["facets"] for r in records], results),
            "tasks": records,
        }

    def markdown(self, doc: dict[str, Any]) -> str:
        """The report: the PRS table, SR per kind of instruction, outcomes and failures."""
        m = doc["metrics"]
        summary = Summary(**{k: m[k] for k in Summary.model_fields})
        lines = [
            f"# Benchmark report: delivery / agent {doc['agent']}",
            "",
            f"Split {doc['split']}, building {doc['building']}, seed {doc.get('seed')}, "
            f"trials {doc.get('trials')}, backend {doc.get('backend')}.",
            "",
            f"**Task SR {m['task_sr']:.1f}%**, score (partial credit) {m['score']:.3f}.",
            "",
            "## PRS table",
            "",
            summary_table(summary),
            "## By kind of instruction",
            "",
            "Category = how the object is described, level = how the recipient is referred to.",
            "",
            breakdown_table(doc["breakdown"]),
            "## By cell (category / level)",
            "",
            *_group_table(doc["by_cell"], "cell"),
            "",
            "## Outcomes",
            "",
            "| outcome | episodes |",
            "|---|---:|",
            *(f"| {k} | {v} |" for k, v in m["outcomes"].items()),
            "",
        ]
        failures = [t for t in doc["tasks"] if not t["success"]]
        lines.append(f"## Failures ({len(failures)})")
        lines.extend(f"- `{t['id']}` (trial {t['trial']}): {t['reason']}" for t in failures[:200])
        return "\n".join(lines) + "\n"

    def summary_text(self, doc: dict[str, Any]) -> str:
        """The PRS table for the terminal."""
        m = doc["metrics"]
        head = f"delivery / {doc['agent']} on {doc['split']}: Task SR {m['task_sr']:.1f}% ({m['episodes']} episodes)"
        return head + "\n" + summary_table(Summary(**{k: m[k] for k in Summary.model_fields})).rstrip("\n")


def _group_table(groups: dict[str, dict[str, Any]], first: str) -> list[str]:
    lines = [
        f"| {first} | episodes | Task SR | Manipulation SR | Human-search SR | mean time |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, g in groups.items():
        lines.append(
            f"| {name} | {g['episodes']} | {g['task_sr']:.1f}% | {g['manipulation_sr']:.1f}% "
            f"| {g['human_search_sr']:.1f}% | {g['mean_time']:.1f} s |"
        )
    return lines


def _check_tasks(tasks: list[DeliveryTask], building: Building, source: str) -> None:
    """Tasks from a file must refer to this building's objects and people."""
    items = {it.id for it in building.items}
    people = {p.id for p in building.people}
    for t in tasks:
        if t.item not in items:
            raise GSRError(f"{source}: task {t.id}: object {t.item!r} is not in building {building.name}")
        if t.person not in people:
            raise GSRError(f"{source}: task {t.id}: person {t.person!r} is not in building {building.name}")


SUITE = DeliverySuite()
