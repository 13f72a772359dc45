"""Run the baseline agent over a split of the delivery benchmark and summarize the results."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from gsr.benchmarks.delivery.agent import AgentTrace, BaselineAgent
from gsr.benchmarks.delivery.building.checks import building_problems
from gsr.benchmarks.delivery.building.graph import building_graph
from gsr.benchmarks.delivery.building.model import Building, load_building
from gsr.benchmarks.delivery.building.navigation import BuildingMap
from gsr.benchmarks.delivery.building.shipped import load_shipped_building
from gsr.benchmarks.delivery.metrics import EpisodeResult, Summary, score_episode, summarize
from gsr.benchmarks.delivery.parser import InstructionParser, lexicon_from_graph
from gsr.benchmarks.delivery.tasks import DeliveryTask, generate_tasks
from gsr.benchmarks.delivery.world import DeliveryWorld

from gsr.errors import GSRError


def checked_building(path: Path | None) -> Building:
    """The shipped building, or a user's file checked against the building invariants."""
    if path is None:
        return load_shipped_building()
    building = load_building(path)
    problems = building_problems(building)
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise GSRError(f"{path}: unusable building: {problems[0]}{more}")
    return building


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


def make_agent(building: Building, bmap: BuildingMap, agent_name: str = "baseline") -> BaselineAgent:
    """One of :data:`AGENTS` for a building; ValueError naming the known ones otherwise."""
    if agent_name not in AGENTS:
        raise ValueError(f"unknown agent {agent_name!r} (known: {', '.join(AGENTS)})")
    return BaselineAgent(building, bmap, parser_for(building), use_routines=agent_name == "baseline")


def play(
    building: Building, bmap: BuildingMap, agent: BaselineAgent, task: DeliveryTask
) -> tuple[EpisodeResult, AgentTrace]:
    """One episode, the unit both ``gsr delivery run`` and ``gsr bench run delivery`` execute:
    a fresh world for the task, the agent's run in it, and the episode's score."""
    world = DeliveryWorld(building, bmap, task)
    trace = agent.run(world)
    return score_episode(task, world, trace), trace


def run_tasks(
    building: Building, tasks: list[DeliveryTask], split: str = "custom", agent_name: str = "baseline"
) -> RunOutput:
    """Run an agent on ``tasks`` (one simulated world per task) and score every episode."""
    bmap = BuildingMap(building)
    agent = make_agent(building, bmap, agent_name)
    results = []
    start = time.perf_counter()
    for task in tasks:
        results.append(play(building, bmap, agent, task)[0])
    wall = time.perf_counter() - start
    return RunOutput(tasks, results, summarize(split, results, wall))


def run_split(
    building: Building, split: str = "test", limit: int | None = None, agent_name: str = "baseline"
) -> RunOutput:
    """Generate a split's tasks (optionally the first ``limit``) and run an agent on them."""
    return run_tasks(building, generate_tasks(building, split, limit), split, agent_name)
