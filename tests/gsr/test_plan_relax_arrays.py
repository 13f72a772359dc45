"""The relaxation/kernel contract (gsr.plan.relax_arrays): what the kernels read, the relaxation has."""

from __future__ import annotations

import ast
from pathlib import Path

import gsr.plan.relax_c
import gsr.plan.relax_jit
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.plan.relax_arrays import UnaryRelaxation

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl"


def _read_by_kernels() -> set[str]:
    """Every ``relax.<name>`` the kernel modules read off the relaxation they are given."""
    names = set()
    for module in (gsr.plan.relax_c, gsr.plan.relax_jit):
        tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id == "relax"
            ):
                names.add(node.attr)
    return names


def test_the_protocol_names_everything_the_kernels_read() -> None:
    read = _read_by_kernels()
    assert {"pre", "add", "pre_of", "goal_fact"} <= read  # the scan sees the kernels' reads
    assert read <= set(UnaryRelaxation.__annotations__), read - set(UnaryRelaxation.__annotations__)


def test_a_relaxation_is_a_unary_relaxation() -> None:
    task = ground_task(
        load_domain(FIXTURES / "miconic-simpleadl" / "domain.pddl"),
        load_problem(FIXTURES / "miconic-simpleadl" / "s4-0.pddl"),
    )
    relax = Relaxation(task)
    assert isinstance(relax, UnaryRelaxation)
    assert len(relax.pre) == len(relax.add) == len(relax.cost) == len(relax.owner) == len(relax.npre)
    assert len(relax.pre_of) == relax.n_facts
