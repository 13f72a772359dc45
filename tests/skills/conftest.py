"""Fixtures for the skills tests: LIBERO goal tasks as TaskSpecs, worlds built from them."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pybullet")

from gsr.libero import libero_task
from gsr.pddl.bddl import parse_bddl
from gsr.task_spec import TaskSpec


def libero_goal_task(libero_dir: Path, name: str, goal: str = "(and)") -> TaskSpec:
    """A TaskSpec (no layout: the world generates one) for a LIBERO goal-suite BDDL file."""
    path = libero_dir / "libero_goal" / f"{name}.bddl"
    graph, _problem = libero_task(parse_bddl(path.read_text(encoding="utf-8")))
    return TaskSpec(
        id=name, suite="libero_goal", instructions=(name.replace("_", " "),), initial=graph, goal=goal
    )


@pytest.fixture
def bowl_task(libero_dir: Path) -> TaskSpec:
    """LIBERO goal 'put the bowl on the plate' with its goal formula."""
    return libero_goal_task(libero_dir, "put_the_bowl_on_the_plate", "(on akita_black_bowl_1 plate_1)")


@pytest.fixture
def bowl_world(bowl_task: TaskSpec):
    """A built world for the bowl task (seed 0), closed after the test."""
    from gsr.skills.build import build_world

    world = build_world(bowl_task, seed=0)
    yield world
    world.close()
