"""Helpers for the language tests: goal equivalence by ground DNF, and the reference data sets."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.facts import problem_from_graph
from gsr.pddl.model import Domain, Formula
from gsr.plan.ground import _TypedObjects
from gsr.plan.normalize import ground_simplify, nnf, to_dnf
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.semantics import compile_domain


def ground_dnf(formula: Formula, graph: SceneGraph, domain: Domain | None = None) -> frozenset:
    """The goal over the graph's objects as a set of conjunctions of fluent literals.

    Quantifiers are expanded over the typed objects and static atoms (colours, affordances, part_of)
    evaluated in the graph, exactly as the planner compiles a goal. Two goals with the same DNF have
    the same satisfying states among the states reachable from the graph (statics never change).
    """
    domain = domain or load_builtin_domain("tabletop")
    problem = problem_from_graph(graph, formula, domain=domain)
    fluents = compile_domain(domain).fluents
    objects = _TypedObjects(domain, problem.all_objects(domain))

    def static(atom):
        return None if atom.predicate in fluents else atom in problem.init

    return frozenset(to_dnf(ground_simplify(nnf(formula), {}, objects, static)))


@pytest.fixture(scope="session")
def domain() -> Domain:
    """The tabletop domain."""
    return load_builtin_domain("tabletop")


@pytest.fixture(scope="session")
def libero_files(shared_data: Path) -> list[Path]:
    """The 40 LIBERO task files."""
    files = sorted((shared_data / "libero").glob("*/*.bddl"))
    assert len(files) == 40
    return files


@pytest.fixture(scope="session")
def gsr_bench_configs(shared_data: Path) -> list[dict]:
    """The 90 GSR-Bench dev configs."""
    import yaml

    data = yaml.safe_load((shared_data / "gsr_bench" / "saved_configs_dev.yaml").read_text(encoding="utf-8"))
    configs = data["configs"]
    assert len(configs) == 90
    return configs
