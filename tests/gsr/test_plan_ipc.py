"""Planner on the IPC sets: validated plans, and optimal costs equal to Fast Downward's."""

from __future__ import annotations

import functools

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan
from gsr.plan.fast_downward import find_fast_downward, run_fast_downward
from gsr.validate import validate_plan
from tests.data_paths import PDDL as DATA

SATISFICING = [
    ("blocks", "probBLOCKS-4-0.pddl"),
    ("blocks", "probBLOCKS-9-0.pddl"),
    ("blocks", "probBLOCKS-12-1.pddl"),
    ("gripper", "prob05.pddl"),
    ("miconic-simpleadl", "s6-2.pddl"),
]
OPTIMAL = (
    [("blocks", f"probBLOCKS-{n}-{i}.pddl") for n in (4, 5, 6) for i in range(3)]
    + [("gripper", f"prob0{i}.pddl") for i in (1, 2, 3)]
    + [("miconic-simpleadl", f"s{n}-{i}.pddl") for n in (1, 2, 3) for i in range(5)]
)


@functools.cache
def _load(domain_set: str, name: str) -> tuple:
    domain = load_domain(DATA / domain_set / "domain.pddl")
    return domain, load_problem(DATA / domain_set / name, domain)


@pytest.mark.parametrize(("domain_set", "name"), SATISFICING)
@pytest.mark.parametrize("planner", ["lazy-ff", "gbfs-ff"])
def test_satisficing_plans_validate(domain_set: str, name: str, planner: str) -> None:
    domain, problem = _load(domain_set, name)
    result = plan(domain, problem, planner=planner, timeout=60)
    assert result.status == "solved", result.message
    report = validate_plan(domain, problem, result.plan)
    assert report.valid
    assert result.cost == len(result.plan)
    assert result.expanded > 0 and result.evaluated > 0


@pytest.mark.parametrize(("domain_set", "name"), OPTIMAL)
def test_optimal_cost_matches_fast_downward(domain_set: str, name: str) -> None:
    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    domain, problem = _load(domain_set, name)
    result = plan(domain, problem, planner="astar-lmcut", timeout=120)
    assert result.status == "solved", result.message
    assert validate_plan(domain, problem, result.plan).valid
    # FD's LM-cut rejects conditional effects; its h_max accepts them and is admissible too.
    search = "astar(hmax())" if domain_set == "miconic-simpleadl" else "astar(lmcut())"
    status, fd_plan, message = run_fast_downward(
        DATA / domain_set / "domain.pddl", DATA / domain_set / name, 120, search=search
    )
    assert status == "solved", message
    assert result.cost == len(fd_plan)


def test_miconic_conditional_effects_with_hmax_and_bfs() -> None:
    domain, problem = _load("miconic-simpleadl", "s2-3.pddl")
    costs = set()
    for planner in ("astar-hmax", "bfs", "astar-blind"):
        result = plan(domain, problem, planner=planner, timeout=30)
        assert result.status == "solved"
        assert validate_plan(domain, problem, result.plan).valid
        costs.add(result.cost)
    assert len(costs) == 1


def test_fd_delegation_round_trip() -> None:
    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    domain, problem = _load("blocks", "probBLOCKS-5-1.pddl")
    result = plan(domain, problem, planner="fd", timeout=60)
    assert result.status == "solved", result.message
    assert validate_plan(domain, problem, result.plan).valid
