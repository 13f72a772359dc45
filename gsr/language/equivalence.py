"""Goal equivalence by ground DNF: the criterion the grounder's measurements use (LIBERO, datagen)."""

from __future__ import annotations

from gsr.facts import problem_from_graph
from gsr.pddl.model import Domain, Formula
from gsr.pddl.walk import nnf, to_dnf
from gsr.plan.grounding import ObjectsByType, ground_simplify
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
    objects = ObjectsByType(domain, problem.all_objects(domain))

    def static(atom):
        return None if atom.predicate in fluents else atom in problem.init

    return frozenset(to_dnf(ground_simplify(nnf(formula), {}, objects, static)))


def equivalent_goals(a: Formula, b: Formula, graph: SceneGraph, domain: Domain | None = None) -> bool:
    """True when the two goals have the same ground DNF over the graph."""
    return ground_dnf(a, graph, domain) == ground_dnf(b, graph, domain)
