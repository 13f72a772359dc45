"""Shared fixtures for the reasoner tests: a small GSR-Bench scene and the tabletop domain."""

from __future__ import annotations

import pytest

from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.pddl.parser import parse_formula
from gsr.resources import load_builtin_domain
from gsr.step import Goal

SCENE = {
    "nodes": ["table", "blue_box", "red_cube1", "short_cabinet", "short_cabinet/drawer_low(closed)"],
    "edges": ["blue_box(on)table", "red_cube1(on)table", "short_cabinet(on)table"],
}
PICK = "(pick red_cube1 table) +(holding red_cube1) -(hand_empty) -(on red_cube1 table)"
PLACE = (
    "(place_in red_cube1 blue_box) +(in red_cube1 blue_box) +(hand_empty) +(cube_count blue_box n1) "
    "-(holding red_cube1) -(cube_count blue_box n0)"
)


@pytest.fixture(scope="session")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="session")
def graph():
    return graph_from_gsr_bench(SCENE)


@pytest.fixture(scope="session")
def box_goal():
    return Goal(parse_formula("(in red_cube1 blue_box)"), "put the red cube in the blue box")


class Script:
    """A scripted model: replays answers in order and records the prompts it was given."""

    name = "script"

    def __init__(self, replies):
        self.replies = list(replies)
        self.prompts = []
        self.queries = []

    def complete(self, prompt, stop=(), query=None):
        self.prompts.append(prompt)
        self.queries.append(query)
        return self.replies.pop(0) if self.replies else ""
