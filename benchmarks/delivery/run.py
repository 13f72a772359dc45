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

    results: list[EpisodeResult]
    summary: Summary


def run_tasks(building: Building, tasks: list[DeliveryTask], split: str = "custom") -> RunOutput:
    """Run the baseline agent on ``tasks`` (one simulated world per task) and score every episode."""
    bmap = BuildingMap(building)
    agent = BaselineAgent(building, bmap, parser_for(building))
    results = []
    start = time.perf_counter()
    for task in tasks:
        world = DeliveryWorld(building, bmap, task)
        trace = agent.run(world)
        results.append(score_episode(task, world, trace))
    wall = time.perf_counter() - start
    return RunOutput(results, summarize(split, results, wall))


def run_split(building: Building, split: str = "test", limit: int | None = None) -> RunOutput:
    """Generate a split's tasks (optionally the first ``limit``) and run the baseline on them."""
    return run_tasks(building, generate_tasks(building, split, limit), split)
