"""Grounding honours the planner's time limit (a grounding blow-up cannot overrun --timeout)."""

from __future__ import annotations

import time

import pytest

from gsr.pddl.parser import load_domain, load_problem
from gsr.plan import plan
from gsr.plan.grounding import GroundingTimeout, ground_task
from tests.data_paths import PDDL

BLOCKS = PDDL / "blocks"


def _task(name: str):
    domain = load_domain(BLOCKS / "domain.pddl")
    return domain, load_problem(BLOCKS / name, domain)


def test_a_passed_deadline_stops_grounding() -> None:
    domain, problem = _task("probBLOCKS-17-0.pddl")
    with pytest.raises(GroundingTimeout, match="grounding did not finish"):
        ground_task(domain, problem, deadline=time.perf_counter() - 1.0)
    # without a deadline, or with a far one, the same task grounds (same operators)
    far = ground_task(domain, problem, deadline=time.perf_counter() + 3600.0)
    assert len(far.ops) == len(ground_task(domain, problem).ops) > 0


def test_plan_reports_a_grounding_timeout_as_timeout() -> None:
    domain, problem = _task("probBLOCKS-17-0.pddl")
    result = plan(domain, problem, planner="lazy-ff", timeout=0.0)
    assert result.status == "timeout"
    assert result.plan is None and result.expanded == 0
    assert "grounding did not finish" in result.message
    assert plan(domain, problem, planner="lazy-ff", timeout=60.0).status == "solved"
