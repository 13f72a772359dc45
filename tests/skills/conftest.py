"""Fixtures for the skills tests: LIBERO goal tasks as TaskSpecs, worlds built from them."""

from __future__ import annotations

from contextlib import contextmanager
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


#: PyBullet states saved mid-episode (``p.saveBullet``) by the tests that replay a failure from there
SNAPSHOTS = Path(__file__).parent / "data"


@pytest.fixture
def snapshot_world():
    """Open the world of a generated GSR-Bench task (seed 0) at a saved mid-episode state, the arm held
    where the state has it: ``with snapshot_world(task_id, "name.bullet") as world: ...``."""
    import pybullet as p
    from gsr.benchmarks.suites import get_suite
    from gsr.skills.build import build_world

    @contextmanager
    def open_world(task_id: str, snapshot: str):
        task = next(t for t in get_suite("gsr-bench-gen").tasks(None, 0) if t.id == task_id)
        with build_world(task, seed=0) as world:
            p.restoreState(fileName=str(SNAPSHOTS / snapshot), physicsClientId=world.client)
            world.robot.hold(world.robot.q())
            yield world

    return open_world
