"""The compiled per-schema preconditions (gsr.plan.grounding.compiled) ground exactly what the general
path grounds, share memo tables between alpha-equivalent conjuncts, and hand the shapes they do not
hold to the general path."""

from __future__ import annotations

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.pddl.files import find_domain_file
from gsr.pddl.model import And, Atom, Exists, Forall, Not, Or, TypedVar
from gsr.pddl.parser import load_domain, load_problem, parse_domain, parse_problem
from gsr.plan import plan
from gsr.plan.grounding import fixpoint as ground
from gsr.plan.grounding import grounding_tables
from gsr.plan.grounding.compiled import GENERAL, canonical, key_cnf
from gsr.resources import load_builtin_domain


def _fields(task):
    """Everything a search sees of a grounded task."""
    return (
        [(a.predicate, a.args) for a in task.atoms],
        [(o.name, o.args, o.cost, o.pre, o.neg, o.add, o.delete, o.cond) for o in task.ops],
        task.init,
        task.goals,
        [(o.name, o.args, o.pre, o.neg, o.add) for o in task.axioms],
    )


def _both(monkeypatch, domain, problem):
    """The grounded task with the compiled preconditions and with the general path only."""
    monkeypatch.setattr(ground, "COMPILED", True)
    compiled = ground.ground_task(domain, problem)
    monkeypatch.setattr(ground, "COMPILED", False)
    general = ground.ground_task(domain, problem)
    monkeypatch.setattr(ground, "COMPILED", True)
    return compiled, general


@pytest.mark.parametrize("seed", [0, 3, 7, 11, 19])
def test_compiled_tabletop_grounding_equals_the_general_path(monkeypatch, seed) -> None:
    domain = load_builtin_domain("tabletop")
    name, graph, goal, _ = long_tabletop_task(seed)
    problem = problem_from_graph(graph, goal, name=name, domain=domain)
    compiled, general = _both(monkeypatch, domain, problem)
    assert len(compiled.ops) > 50
    assert _fields(compiled) == _fields(general)


_NESTED = """
(define (domain nested)
  (:requirements :strips :typing :negative-preconditions :disjunctive-preconditions
                 :universal-preconditions :existential-preconditions)
  (:types obj)
  (:predicates (p ?x - obj) (q ?x - obj ?y - obj) (r ?x - obj) (s ?x - obj) (done ?x - obj) (link ?x - obj ?y - obj))
  (:action go
    :parameters (?x - obj)
    :precondition (and (r ?x)
      (forall (?y - obj) (or (p ?y) (and (q ?x ?y) (or (r ?y) (s ?x))))))
    :effect (done ?x))
  (:action mark
    :parameters (?x - obj ?y - obj)
    :precondition (and (link ?x ?y) (not (= ?x ?y)) (or (done ?x) (s ?y))
      (not (exists (?z - obj) (q ?z ?y))))
    :effect (and (p ?y) (s ?x) (q ?y ?x) (not (r ?x)))))
"""

_NESTED_PROBLEM = """
(define (problem n1) (:domain nested)
  (:objects a b c - obj)
  (:init (r a) (r b) (q a b) (s c) (link a b) (link b c) (link c a) (link a a))
  (:goal (and (p c) (s b))))
"""


def test_a_deeper_conjunct_goes_to_the_general_path_with_the_same_result(monkeypatch) -> None:
    domain = parse_domain(_NESTED)
    problem = parse_problem(_NESTED_PROBLEM, domain=domain)
    calls = []
    real = ground.general_variant

    def counting(*args, **kwargs):
        calls.append(args[0].name)
        return real(*args, **kwargs)

    monkeypatch.setattr(ground, "general_variant", counting)
    monkeypatch.setattr(ground, "COMPILED", True)
    compiled = ground.ground_task(domain, problem)
    assert "go" in calls  # the (or (p ?y) (and (q ?x ?y) (or ...))) instances are too deep
    assert "mark" not in calls  # a literal, an inequality, an (or ...) and a quantifier: compiled
    monkeypatch.setattr(ground, "COMPILED", False)
    general = ground.ground_task(domain, problem)
    assert _fields(compiled) == _fields(general)
    assert len(compiled.ops) >= 3
    monkeypatch.setattr(ground, "COMPILED", True)
    result = plan(domain, problem)
    assert result.solved, result.message


def test_key_cnf_holds_literals_and_disjunctions_of_conjunctions_only() -> None:
    p, q, r = Atom("p", ("a",)), Atom("q", ("a",)), Atom("r", ("b",))
    pos, neg, choices, relax = key_cnf(And((p, Not(q), Or((r, And((q, Not(p))))))))  # type: ignore[misc]
    assert pos == (("p", ("a",)),) and neg == (("q", ("a",)),)
    assert choices == (
        (
            (((("r", ("b",)),), ()), ((("q", ("a",)),), (("p", ("a",)),))),
            ((("r", ("b",)),), (("q", ("a",)),)),
        ),
    )
    assert relax == (((("r", ("b",)),), (("q", ("a",)),)),)  # per choice: each alternative's positives
    # An alternative without a positive literal: the choice always holds relaxed.
    assert key_cnf(Or((r, Not(q))))[3] == ()  # type: ignore[index]
    assert key_cnf(Or((r, And((q, Or((p, r))))))) is GENERAL


def test_alpha_equivalent_conjuncts_share_one_canonical_form() -> None:
    thing = ("thing",)
    a = Not(Exists((TypedVar("?z", thing),), Atom("on", ("?z", "?o"))))
    b = Not(Exists((TypedVar("?y", thing),), Atom("on", ("?y", "?c"))))
    c = Not(Exists((TypedVar("?y", thing),), Atom("in", ("?y", "?c"))))
    assert canonical(a)[0] == canonical(b)[0] != canonical(c)[0]
    assert canonical(a)[1] == ("?o",) and canonical(b)[1] == ("?c",)
    two = Forall((TypedVar("?d", thing),), Or((Not(Atom("above", ("?d", "?x"))), Atom("on", ("?w", "?d")))))
    assert canonical(two)[1] == ("?x", "?w")  # free variables in order of first occurrence


def test_tabletop_schemas_share_memo_tables() -> None:
    tables = grounding_tables(load_builtin_domain("tabletop"))
    memos = [m for f in tables.factories for m in f.memos]
    # (not (exists (?z) (on ?z ?x))) and the drawer rule recur in pick, place_in, open, close, ...
    assert len(memos) > len(set(memos)) + 5


def test_a_quantifier_over_all_the_variables_is_memoised_and_shared() -> None:
    tables = grounding_tables(load_builtin_domain("tabletop"))
    by_name = {s.name: f for s, f in zip(tables.schemas, tables.factories, strict=True)}
    # open's and close's "no open drawer above ?x" mention the action's one variable: one table
    # for both, and open's "nothing on ?x" as its literal keys, with no Simplifier call per binding
    assert set(by_name["open"].memos) & set(by_name["close"].memos)
    assert "key_cnf(simplify(" not in by_name["open"].source
    assert "for q_ in O0" in by_name["open"].source


@pytest.mark.parametrize(
    "problem",
    [
        "miconic-simpleadl/s6-0.pddl",
        "openstacks-sat08-adl/p05.pddl",
        "logistics00/probLOGISTICS-10-0.pddl",
        "rovers/p10.pddl",
        "driverlog/p10.pddl",
    ],
)
def test_compiled_ipc_grounding_equals_the_general_path(monkeypatch, shared_data, problem) -> None:
    path = shared_data / "pddl" / problem
    domain = load_domain(find_domain_file(path))
    compiled, general = _both(monkeypatch, domain, load_problem(path, domain))
    assert _fields(compiled) == _fields(general)


def test_memo_tables_are_numbered_once_per_domain() -> None:
    from gsr.plan.grounding import ObjectsByType
    from gsr.plan.grounding.compiled import bind
    from gsr.plan.grounding.simplify import Simplifier

    domain = load_builtin_domain("tabletop")
    tables = grounding_tables(domain)
    _, graph, goal, _ = long_tabletop_task(2)
    problem = problem_from_graph(graph, goal, domain=domain)
    simplify = Simplifier(ObjectsByType(domain, problem.all_objects(domain)), tables.fluent, problem.init)
    shared: dict = {}
    for factory in tables.factories:
        if factory is not None:
            bind(factory, simplify, lambda b: None, shared)
    keys = {key for f in tables.factories if f is not None for key in f.memos}
    # One table per distinct (kind, alpha-renamed conjunct) of all the schemas, found by a small
    # number (no formula hashed per problem); equal conjuncts of two schemas share it.
    assert len(shared) == len(keys)
    assert all(type(k) is int for k in shared)
    assert sorted(shared) == list(range(len(keys)))
