"""Run the baseline agent over a split of the delivery benchmark and summarize the results."""

from __future__ import annotations

import time
from dataclasses import dataclass

from benchmarks.delivery.agent import BaselineAgent
from benchmarks.delivery.metrics import EpisodeResult, Summary, score_episode, summarize
from benchmarks.delivery.parser import InstructionParser, lexicon_from_graph
from benchmarks.delivery.tasks import DeliveryTask, generate_tasks
from benchmarks.delivery.world import DeliveryWorld
from gsr.building.graph import building_graph
from gsr.building.model import Building
from gsr.building.navigation import BuildingMap


def parser_for(building: Building) -> InstructionParser:
    """The instruction parser whose lexicon is this building's graph (with its residents)."""
    graph = building_graph(building, people_rooms={p.id: p.home_room for p in building.people})
    return InstructionParser(lexicon_from_graph(graph))


@dataclass
class RunOutput:
    """Per-episode results and their summary."""

    tasks: list[DeliveryTask]
    results: list[EpisodeResult]
    summary: Summary


AGENTS: dict[str, str] = {
    "baseline": "parse, search receptacles nearest-first, find people via sightings, hints and routines",
    "no-routines": "ablation: the baseline without people's published routines",
}


def run_tasks(
    building: Building, tasks: list[DeliveryTask], split: str = "custom", agent_name: str = "baseline"
) -> RunOutput:
    """Run an agent on ``tasks`` (one simulated world per task) and score every episode."""
    if agent_name not in AGENTS:
        raise ValueError(f"unknown agent {agent_name!r} (known: {', '.join(AGENTS)})")
    bmap = BuildingMap(building)
    agent = BaselineAgent(building, bmap, parser_for(building), use_routines=agent_name == "baseline")
    results = []
    start = time.perf_counter()
    for task in tasks:
        world = DeliveryWorld(building, bmap, task)
        trace = agent.run(world)
        results.append(score_episode(task, world, trace))
    wall = time.perf_counter() - start
    return RunOutput(tasks, results, summarize(split, results, wall))


def run_split(
    building: Building, split: str = "test", limit: int | None = None, agent_name: str = "baseline"
) -> RunOutput:
    """Generate a split's tasks (optionally the first ``limit``) and run an agent on them."""
    return run_tasks(building, generate_tasks(building, split, limit), split, agent_name)
