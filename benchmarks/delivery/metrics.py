"""Episode results and the PRS-style summary: Task SR, parsing accuracy, manipulation SR, human search."""

from __future__ import annotations

from gsr.benchmarks.delivery.agent import AgentTrace
from gsr.benchmarks.delivery.tasks import DeliveryTask
from gsr.benchmarks.delivery.world import DeliveryWorld
from pydantic import BaseModel, ConfigDict


class EpisodeResult(BaseModel):
    """Scores of one episode (partial scores as in the PRS benchmark)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    task: str
    success: bool
    parse_correct: bool
    object_found: bool
    grasped: bool
    person_within_5m: bool
    person_within_3m: bool
    timed_out: bool
    time: float  # simulated seconds used
    metres: float
    actions: int
    note: str = ""


def score_episode(task: DeliveryTask, world: DeliveryWorld, trace: AgentTrace) -> EpisodeResult:
    """Score a finished episode: success = right object handed to the right person within 3 m in time."""
    log = world.log
    note = trace.parse_error or "; ".join(trace.notes)
    return EpisodeResult(
        task=task.id,
        success=log.delivered and world.elapsed <= task.time_limit,
        parse_correct=trace.parsed == task.reference,
        object_found=log.object_found,
        grasped=log.grasped,
        person_within_5m=log.person_within_5m,
        person_within_3m=log.person_within_3m,
        timed_out=log.timed_out,
        time=round(world.elapsed, 3),
        metres=round(log.metres, 3),
        actions=log.actions,
        note=note,
    )


class Summary(BaseModel):
    """Aggregate figures of a run (rates in percent, times in simulated seconds)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    split: str
    episodes: int
    task_sr: float
    parsing_accuracy: float
    object_found: float
    manipulation_sr: float
    human_search_sr: float
    human_within_5m: float
    timeouts: float
    mean_time: float
    mean_time_success: float
    sim_seconds_per_wall_second: float


def summarize(split: str, results: list[EpisodeResult], wall_seconds: float) -> Summary:
    """The PRS-style table row of a run."""
    n = len(results)
    if n == 0:
        raise ValueError("no episodes to summarize")

    def pct(flag: str) -> float:
        return round(100.0 * sum(bool(getattr(r, flag)) for r in results) / n, 1)

    wins = [r.time for r in results if r.success]
    sim = sum(r.time for r in results)
    return Summary(
        split=split,
        episodes=n,
        task_sr=pct("success"),
        parsing_accuracy=pct("parse_correct"),
        object_found=pct("object_found"),
        manipulation_sr=pct("grasped"),
        human_search_sr=pct("person_within_3m"),
        human_within_5m=pct("person_within_5m"),
        timeouts=pct("timed_out"),
        mean_time=round(sim / n, 1),
        mean_time_success=round(sum(wins) / len(wins), 1) if wins else 0.0,
        sim_seconds_per_wall_second=round(sim / wall_seconds, 1) if wall_seconds > 0 else 0.0,
    )


def summary_table(s: Summary) -> str:
    """A Markdown table in the layout of the PRS paper's results."""
    rows = [
        ("Episodes", f"{s.episodes} ({s.split})"),
        ("Task SR", f"{s.task_sr:.1f}%"),
        ("Parsing accuracy", f"{s.parsing_accuracy:.1f}%"),
        ("Object found", f"{s.object_found:.1f}%"),
        ("Manipulation SR (target grasped)", f"{s.manipulation_sr:.1f}%"),
        ("Human-search SR (within 3 m)", f"{s.human_search_sr:.1f}%"),
        ("Human found within 5 m", f"{s.human_within_5m:.1f}%"),
        ("Timed out (8 min)", f"{s.timeouts:.1f}%"),
        ("Mean time, all episodes", f"{s.mean_time:.1f} s"),
        ("Mean time, successful episodes", f"{s.mean_time_success:.1f} s"),
        ("Simulated seconds per wall second", f"{s.sim_seconds_per_wall_second:.0f}"),
    ]
    return "| metric | value |\n|---|---|\n" + "".join(f"| {k} | {v} |\n" for k, v in rows)


def _object_facet(task: DeliveryTask) -> str:
    o = task.reference.object
    parts = [name for name, v in (("colour", o.color), ("receptacle", o.receptacle), ("room", o.room)) if v]
    return "+".join(parts) or "category only"


def _person_facet(task: DeliveryTask) -> str:
    p = task.reference.person
    parts = [
        name
        for name, v in (("name", p.name), ("role", p.role), ("clothes", p.garment), ("hair", p.hair))
        if v is not None
    ]
    return "+".join(parts) or "gender only"


def facets(task: DeliveryTask) -> dict[str, str]:
    """How the instruction refers to things: object description, recipient reference, recipient's room."""
    return {
        "object described by": _object_facet(task),
        "recipient referred to by": _person_facet(task),
        "recipient's room given": "yes" if task.reference.person.room else "no",
    }


def breakdown(tasks: list[DeliveryTask], results: list[EpisodeResult]) -> list[dict[str, object]]:
    """Task SR and human-search SR per kind of instruction (how object and person are referred to)."""
    if [t.id for t in tasks] != [r.task for r in results]:
        raise ValueError("tasks and results are not the same episodes in the same order")
    return breakdown_by([facets(t) for t in tasks], results)


def breakdown_by(keys: list[dict[str, str]], results: list[EpisodeResult]) -> list[dict[str, object]]:
    """The breakdown from each episode's :func:`facets` (in episode order)."""
    rows: list[dict[str, object]] = []
    for facet in ("object described by", "recipient referred to by", "recipient's room given"):
        groups: dict[str, list[EpisodeResult]] = {}
        for k, r in zip(keys, results, strict=True):
            groups.setdefault(k[facet], []).append(r)
        for value, rs in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            rows.append(
                {
                    "facet": facet,
                    "value": value,
                    "episodes": len(rs),
                    "task_sr": round(100.0 * sum(r.success for r in rs) / len(rs), 1),
                    "human_search_sr": round(100.0 * sum(r.person_within_3m for r in rs) / len(rs), 1),
                    "mean_time": round(sum(r.time for r in rs) / len(rs), 1),
                }
            )
    return rows


def breakdown_table(rows: list[dict[str, object]]) -> str:
    """The breakdown as a Markdown table."""
    out = "| facet | value | episodes | Task SR | Human-search SR | mean time |\n|---|---|---:|---:|---:|---:|\n"
    for r in rows:
        out += (
            f"| {r['facet']} | {r['value']} | {r['episodes']} | {r['task_sr']:.1f}% "
            f"| {r['human_search_sr']:.1f}% | {r['mean_time']:.1f} s |\n"
        )
    return out
