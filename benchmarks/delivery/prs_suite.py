"""``gsr bench run prs --source DIR``: the PRS delivery benchmark as an episode suite of the runner.

The source is a PRS data folder (default ``$GSR_SHARED_DATA/prs``); the tasks are its
``delivery_tasks_dev.json`` unless ``--tasks FILE`` names another PRS task file. Each episode runs the
offline PRS environment and agent (``gsr.benchmarks.delivery.prs_run``); the document carries PRS's metrics
and the submission in PRS's result format (also written as ``prs_submission.json`` by
``gsr delivery prs``). The generated-building suite stays ``delivery``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from gsr.benchmarks.delivery.prs_metrics import aggregate
from gsr.benchmarks.delivery.prs_run import ensure_state, run_one, task_ids

from gsr.episode import EpisodeOptions
from gsr.errors import GSRError
from gsr.resources import shared_data_dir


@dataclass(frozen=True)
class PrsJobConfig:
    """Picklable job config: the data folder, the task file and the caption source."""

    data: str
    tasks: str
    captions: str = "dev"


def prs_job(payload: dict[str, Any], trial: int, config: PrsJobConfig) -> dict[str, Any]:
    """Worker entry: one PRS task (deterministic: trials repeat it)."""
    ensure_state(config.data, config.tasks, config.captions)
    row = run_one(payload["id"])
    rec = row["record"]
    return {
        "id": payload["id"],
        "suite": "prs",
        "category": "delivery",
        "level": None,
        "trial": trial,
        "success": rec["success"],
        "score": round((rec["grasp"] + rec["human_found"] + rec["deliver"] + rec["success"]) / 4, 4),
        "reason": rec["failure_reason"] or f"delivered in {rec['sim_minutes']:.2f} simulated min",
        "time": rec["sim_minutes"] * 60,
        **{
            k: rec[k]
            for k in ("grasp", "object_found", "human_found", "deliver", "sim_minutes", "failure_reason")
        },
        "submission": row["submission"],
    }


class PrsSuite:
    """The ``prs`` suite: PRS's own station, people and tasks, scored by PRS's rules."""

    name = "prs"
    agents: ClassVar[dict[str, str]] = {
        "search": "the PRS search agent (parse, rank rooms, look, grasp, find by appearance)"
    }
    default_agent = "search"

    def prepare(self, options: EpisodeOptions) -> tuple[list[dict[str, Any]], PrsJobConfig]:
        """Check the folder and task file; one payload per task."""
        agent = options.agent or self.default_agent
        if agent not in self.agents:
            raise GSRError(f"suite prs: unknown agent {agent!r}; choose one of {', '.join(self.agents)}")
        if options.split:
            raise GSRError("suite prs: no --split; pass --tasks FILE for another PRS task file")
        data = Path(options.source) if options.source else shared_data_dir() / "prs"
        if not data.is_dir():
            raise GSRError(f"suite prs: {data} is not a folder (pass --source PRS_DATA_DIR)")
        tasks = Path(options.tasks) if options.tasks else data / "delivery_tasks_dev.json"
        config = PrsJobConfig(str(data.resolve()), str(tasks.resolve()))
        ensure_state(config.data, config.tasks, config.captions)
        ids = task_ids()[: options.limit] if options.limit else task_ids()
        return [{"id": i} for i in ids], config

    def job(self) -> Any:
        """:func:`prs_job`."""
        return prs_job

    def document(self, records: list[dict[str, Any]], config: PrsJobConfig, **meta: Any) -> dict[str, Any]:
        """results.json: PRS's metrics, failure reasons, the submission and every episode."""
        if not records:
            raise GSRError("suite prs: no episodes to summarize")
        first = [r for r in records if r["trial"] == 0]
        annotated = len(first)
        scores = [
            {"success": r["success"], "grasp": r["grasp"], "human_found": r["human_found"],
             "minutes": r["sim_minutes"]}
            for r in first
        ]  # fmt: skip
        metrics = aggregate(scores, annotated)
        metrics["success_rate"] = round(sum(r["success"] for r in records) / len(records), 4)
        reasons: dict[str, int] = {}
        for r in first:
            if r["failure_reason"]:
                reasons[r["failure_reason"]] = reasons.get(r["failure_reason"], 0) + 1
        metrics["failure_reasons"] = reasons
        return {
            "suite": self.name,
            "agent": self.default_agent,
            "data": config.data,
            "tasks_file": config.tasks,
            "captions": config.captions,
            **meta,
            "success_rate": metrics["success_rate"],
            "metrics": metrics,
            "submission": {r["id"]: r["submission"] for r in first},
            "tasks": [{k: v for k, v in r.items() if k != "submission"} for r in records],
        }

    def markdown(self, doc: dict[str, Any]) -> str:
        """The report: PRS's table and the failures by reason."""
        m = doc["metrics"]
        lines = [
            "# Benchmark report: prs / agent search",
            "",
            f"PRS data {doc['data']}, tasks {doc['tasks_file']}, captions {doc['captions']}.",
            "",
            "| scorer | Task SR | Object Manipulation SR | Human Search SR | Time Used (min) |",
            "|---|---:|---:|---:|---:|",
            f"| simulator rule | {m['Task SR']:.3f} | {m['Object Manipulation SR']:.3f} "
            f"| {m['Human Search SR']:.3f} | {m['Time Used']:.2f} |",
            f"| eval.py as published | {m['eval.py']['Task SR']:.3f} | "
            f"{m['eval.py']['Object Manipulation SR']:.3f} | {m['eval.py']['Human Search SR']:.3f} "
            f"| {m['eval.py']['Time Used']:.2f} |",
            "",
            "eval.py never sets object_find, so its Task SR is 0 for every submission; the simulator rule "
            "counts a task with the exact object delivered within 3 m in 10 minutes.",
            "",
            "## Failures by reason",
            "",
            "| reason | tasks |",
            "|---|---:|",
            *(f"| {k} | {v} |" for k, v in sorted(m["failure_reasons"].items(), key=lambda kv: -kv[1])),
            "",
        ]
        return "\n".join(lines)

    def summary_text(self, doc: dict[str, Any]) -> str:
        """One line for the terminal."""
        m = doc["metrics"]
        return (
            f"prs / search: Task SR {m['Task SR']:.3f}, Object Manipulation SR {m['Object Manipulation SR']:.3f}, "
            f"Human Search SR {m['Human Search SR']:.3f}, Time Used {m['Time Used']:.2f} min "
            f"({len(doc['tasks'])} episodes)"
        )


def submission_json(doc: dict[str, Any]) -> str:
    """The PRS submission of a results document."""
    return json.dumps(doc["submission"], indent=1)


SUITE = PrsSuite()
