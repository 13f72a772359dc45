"""The IPC language beyond ADL that Fast Downward accepts: derived predicates (axioms), a type under
several parents, repeated variables in predicate declarations; and validation that never grounds."""

from __future__ import annotations

import time

import pytest

from gsr.errors import GSRError, ParseError
from gsr.pddl.axioms import derive, strata
from gsr.pddl.model import Atom
from gsr.pddl.parser import load_domain, load_problem, parse_domain, parse_problem
from gsr.pddl.writer import write_domain
from gsr.plan import PLANNERS, plan
from gsr.step import Plan, Step
from gsr.validate import validate_plan
from tests.data_paths import PDDL

# A graph whose reachability is derived: `link` needs two nodes that are not connected yet,
# `finish` needs a path a -> d, no path b -> a and no direct edge a -> d.
GRAPH = """(define (domain graph) (:requirements :typing :derived-predicates :negative-preconditions)
 (:types node)
 (:constants a b c d - node)
 (:predicates (edge ?x ?y - node) (path ?x ?y - node) (apart ?x ?y - node) (done))
 (:derived (path ?x ?y - node) (edge ?x ?y))
 (:derived (path ?x ?y - node) (exists (?z - node) (and (edge ?x ?z) (path ?z ?y))))
 (:derived (apart ?x ?y - node) (not (path ?x ?y)))
 (:action link :parameters (?x ?y - node) :precondition (and (apart ?x ?y) (not (= ?x ?y)))
  :effect (edge ?x ?y))
 (:action unlink :parameters (?x ?y - node) :precondition (edge ?x ?y) :effect (not (edge ?x ?y)))
 (:action finish :precondition (and (path a d) (not (path b a)) (not (edge a d))) :effect (done)))"""
PROBLEM = """(define (problem p) (:domain graph) (:objects)
 (:init (edge a b) (edge b c) (edge b a)) (:goal (done)))"""


@pytest.fixture(scope="module")
def graph():
    domain = parse_domain(GRAPH)
    return domain, parse_problem(PROBLEM, domain=domain)


def test_derived_predicates_parse_write_and_stratify(graph) -> None:
    domain, _ = graph
    assert [a.name for a in domain.axioms] == ["path", "path", "apart"]
    assert domain.derived == {"path", "apart"}
    assert strata(domain) == [["path"], ["apart"]]  # apart negates path: a higher stratum
    again = parse_domain(write_domain(domain))
    assert again.axioms == domain.axioms


def test_derive_is_the_stratified_fixpoint(graph) -> None:
    domain, problem = graph
    atoms = derive(domain, problem.all_objects(domain), problem.init | {Atom("path", ("d", "a"))})
    paths = {a.args for a in atoms if a.predicate == "path"}
    assert paths == {("a", "b"), ("a", "c"), ("a", "a"), ("b", "c"), ("b", "a"), ("b", "b")}
    apart = {a.args for a in atoms if a.predicate == "apart"}
    assert ("d", "a") in apart and ("a", "b") not in apart and len(apart) == 16 - len(paths)


def test_rules_errors() -> None:
    with pytest.raises(GSRError, match="not stratifiable"):
        strata(
            parse_domain(
                "(define (domain d) (:predicates (p) (q)) (:derived (p) (not (q))) (:derived (q) (p)))"
            )
        )
    with pytest.raises(GSRError, match="changed by action"):
        parse_domain("(define (domain d) (:predicates (p)) (:derived (p) (and)) (:action a :effect (p)))")
    with pytest.raises(GSRError, match="not declared"):
        parse_domain("(define (domain d) (:predicates (p)) (:derived (q) (p)))")


@pytest.mark.parametrize("planner", [p for p in PLANNERS if p != "fd"])
def test_every_planner_plans_with_axioms_and_the_plan_validates(graph, planner: str) -> None:
    domain, problem = graph
    result = plan(domain, problem, planner=planner, timeout=30)
    assert result.status == "solved", result.message
    assert validate_plan(domain, problem, result.plan).valid
    assert result.cost == 3  # link b d (path a d), unlink b a, finish: optimal for every planner here


def test_validation_evaluates_derived_atoms_in_each_state(graph) -> None:
    domain, problem = graph
    assert not validate_plan(domain, problem, Plan((Step("finish", ()),))).valid  # no path a -> d
    report = validate_plan(domain, problem, Plan((Step("link", ("b", "d")), Step("finish", ()))))
    assert report.failed_step == 1 and "path b a" in report.message.replace("(", "")
    # link a b is impossible: a path a -> b already exists (apart a b is false)
    assert validate_plan(domain, problem, Plan((Step("link", ("a", "b")),))).failed_step == 0


def test_unreachable_derived_goal_is_proven_unsolvable() -> None:
    domain = parse_domain(
        "(define (domain d) (:predicates (p ?x) (q ?x) (r ?x)) (:derived (q ?x) (and (p ?x) (r ?x)))"
        " (:action mk :parameters (?x) :effect (p ?x)))"
    )
    problem = parse_problem(
        "(define (problem p) (:domain d) (:objects o) (:init) (:goal (q o)))", domain=domain
    )
    assert plan(domain, problem).status == "unsolvable"


def test_type_under_two_parents_and_repeated_declaration_variables() -> None:
    domain = parse_domain(
        "(define (domain storage) (:requirements :typing)"
        " (:types hoist surface place area - object depot - place storearea transitarea - area"
        "  area crate - surface)"
        " (:predicates (in ?x ?x) (on ?c - crate ?s - storearea)))"
    )
    assert domain.types["area"] == ("surface",)
    assert domain.is_subtype("storearea", "surface") and domain.is_subtype("storearea", "area")
    assert domain.predicates["in"].arity == 2
    assert parse_domain(write_domain(domain)).types == domain.types


def test_an_undeclared_type_in_a_predicate_declaration_stands_for_object() -> None:
    """Fast Downward's translator reads it (a declaration only fixes the arity); elsewhere it is an error."""
    text = (
        "(define (domain ut) (:requirements :typing) (:types block)"
        " (:predicates (p ?x - ghost) (q ?x - block))"
        " (:action a :parameters (?x - block) :precondition (q ?x) :effect (p ?x)))"
    )
    domain = parse_domain(text)
    assert domain.predicates["p"].params[0].types == ("object",)
    problem = parse_problem(
        "(define (problem u) (:domain ut) (:objects b - block) (:init (q b)) (:goal (p b)))", domain=domain
    )
    result = plan(domain, problem)
    assert result.status == "solved" and validate_plan(domain, problem, result.plan).valid
    with pytest.raises(ParseError, match="undeclared type 'ghost'"):
        parse_domain(text.replace(":parameters (?x - block)", ":parameters (?x - ghost)"))


def test_validating_a_plan_never_grounds_the_task() -> None:
    """Tetris' 7-parameter moves over 40 cells: the empty plan is judged (goal false) in seconds."""
    domain = load_domain(PDDL / "tetris" / "domain.pddl")
    problem = load_problem(PDDL / "tetris" / "p04-10.pddl", domain)
    start = time.process_time()
    report = validate_plan(domain, problem, Plan(()))
    assert not report.valid and not report.goal_reached
    assert time.process_time() - start < 15


def test_landmarks_of_a_logistics_like_task_and_the_lama_planner() -> None:
    """Goal facts are landmarks, and preconditions shared by all first achievers precede them."""
    from gsr.plan.grounding import ground_task
    from gsr.plan.landmarks import Landmarks

    domain = parse_domain(
        "(define (domain carry) (:requirements :typing) (:types place box)"
        " (:predicates (at ?b - box ?p - place) (held ?b - box) (road ?p ?q - place) (me ?p - place))"
        " (:action go :parameters (?p ?q - place) :precondition (and (me ?p) (road ?p ?q))"
        "  :effect (and (me ?q) (not (me ?p))))"
        " (:action pick :parameters (?b - box ?p - place) :precondition (and (me ?p) (at ?b ?p))"
        "  :effect (and (held ?b) (not (at ?b ?p))))"
        " (:action drop :parameters (?b - box ?p - place) :precondition (and (me ?p) (held ?b))"
        "  :effect (and (at ?b ?p) (not (held ?b)))))"
    )
    problem = parse_problem(
        "(define (problem p) (:domain carry) (:objects a b c - place x - box)"
        " (:init (me a) (at x b) (road a b) (road b a) (road b c) (road c b)) (:goal (at x c)))",
        domain=domain,
    )
    task = ground_task(domain, problem)
    lm = Landmarks(task)
    names = {lm.describe(k) for k in range(len(lm.facts))}
    assert {"(at x c)", "(held x)", "(me c)", "(me b)"} <= names  # (me b): every pick of x is at b
    init_accepted = lm.accept(0, task.init)
    h, preferred = lm.value(init_accepted, task.init)
    assert h == len(lm.facts) - init_accepted.bit_count() > 0
    assert [str(task.ops[i]) for i in preferred] == ["(go a b)"]
    result = plan(domain, problem, planner="lama")
    assert result.status == "solved" and validate_plan(domain, problem, result.plan).valid
    assert [str(s) for s in result.plan] == ["(go a b)", "(pick x b)", "(go b c)", "(drop x c)"]


def test_fast_downward_agrees_on_derived_predicates(graph) -> None:
    """FD reads the rules our writer emits; its plan passes our validator, at our optimal cost."""
    from gsr.plan.fast_downward import find_fast_downward

    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    domain, problem = graph
    result = plan(domain, problem, planner="fd", timeout=120)
    assert result.status == "solved", result.message
    assert result.cost == 3  # the cost comes from validating FD's plan with gsr.validate


POWER = """(define (domain power) (:requirements :adl :derived-predicates :typing) (:types node)
 (:predicates (source ?n - node) (line ?a ?b - node) (closed ?a ?b - node) (fed ?n - node) (unsafe ?n - node)
  (faulty ?n - node) (ok))
 (:derived (fed ?n - node) (or (source ?n) (exists (?m - node) (and (fed ?m) (line ?m ?n) (closed ?m ?n)))))
 (:derived (unsafe ?n - node) (and (fed ?n) (faulty ?n)))
 (:derived (ok) (not (exists (?n - node) (unsafe ?n))))
 (:action close :parameters (?a ?b - node) :precondition (and (line ?a ?b) (not (closed ?a ?b)) (ok))
  :effect (closed ?a ?b)))"""


def test_derive_on_a_long_closure_matches_a_graph_search() -> None:
    # PSR-style transitive closure over 120 nodes: the joins use bound-argument buckets, so each
    # state is derived in milliseconds (the unindexed join scanned every fed x line pair per node)
    import random

    rng = random.Random(7)
    n = 120
    lines = {(rng.randrange(max(0, i - 6), i), i) for i in range(1, n)}
    closed = {e for e in lines if rng.random() < 0.8}
    faulty = {17, 60}
    domain = parse_domain(POWER)
    objects = {f"n{i}": "node" for i in range(n)}
    atoms = {Atom("source", ("n0",))} | {Atom("line", (f"n{a}", f"n{b}")) for a, b in lines}
    atoms |= {Atom("closed", (f"n{a}", f"n{b}")) for a, b in closed} | {
        Atom("faulty", (f"n{f}",)) for f in faulty
    }
    start = time.process_time()
    state = derive(domain, objects, atoms)
    assert time.process_time() - start < 5.0
    fed, todo = {0}, [0]
    while todo:
        a = todo.pop()
        for x, b in closed:
            if x == a and b not in fed:
                fed.add(b)
                todo.append(b)
    assert {int(a.args[0][1:]) for a in state if a.predicate == "fed"} == fed
    unsafe = fed & faulty
    assert {int(a.args[0][1:]) for a in state if a.predicate == "unsafe"} == unsafe
    assert (Atom("ok", ()) in state) == (not unsafe)


NESTED = """(define (domain nested) (:requirements :adl :derived-predicates :typing) (:types q m n)
 (:predicates (size ?q - q ?n - n) (zero ?n - n) (msg ?q - q ?m - m) (stuck ?q - q) (waits ?q - q ?m - m) (mixed))
 (:derived (stuck ?q - q) (exists (?m - m) (exists (?n - n) (and (msg ?q ?m) (size ?q ?n) (zero ?n)))))
 (:derived (waits ?q - q ?m - m) (and (exists (?x - q) (exists (?n - n) (and (msg ?q ?m) (size ?x ?n) (zero ?n))))))
 (:derived (mixed) (exists (?q - q) (and (stuck ?q) (exists (?q - q) (not (stuck ?q)))))))"""


def test_nested_existentials_are_joined_and_shadowed_names_kept_apart() -> None:
    # Philosophers/optical-telegraph rules nest (exists (?q) (exists (?m) (exists (?n) (and ...)))):
    # every level is joined against the state (before, the inner levels were enumerated over all
    # objects per binding: 1.9 s CPU to validate optical-telegraph's 28-step plan, now 0.3 s).
    domain = parse_domain(NESTED)
    k = 40
    objects = {f"q{i}": "q" for i in range(k)} | {f"m{i}": "m" for i in range(k)} | {"z": "n", "one": "n"}
    atoms = {Atom("zero", ("z",)), Atom("size", ("q1", "z")), Atom("msg", ("q1", "m3"))}
    atoms |= {Atom("size", (f"q{i}", "one")) for i in range(2, k)} | {
        Atom("msg", (f"q{i}", "m0")) for i in range(k)
    }
    start = time.process_time()
    state = derive(domain, objects, atoms)
    assert time.process_time() - start < 1.0
    assert {a.args for a in state if a.predicate == "stuck"} == {("q1",)}
    # one queue is empty, so every message waits (before: ?q, ?m and ?x enumerated, 64,000 bindings)
    assert {a.args for a in state if a.predicate == "waits"} == {
        a.args for a in atoms if a.predicate == "msg"
    }
    # the inner ?q of `mixed` is another variable: some queue is stuck and some (other) queue is not
    assert Atom("mixed", ()) in state
    alone = derive(
        domain, {"q1": "q", "m3": "m", "z": "n"}, {a for a in atoms if "q1" in a.args or a.args == ("z",)}
    )
    assert Atom("stuck", ("q1",)) in alone and Atom("mixed", ()) not in alone
