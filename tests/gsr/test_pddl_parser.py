"""PDDL parser: every IPC reference file, the supported ADL features, and located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from gsr.errors import ParseError
from gsr.pddl import (
    OBJECT,
    TRUE,
    And,
    AndEffect,
    Atom,
    Domain,
    Equals,
    Exists,
    Forall,
    ForallEffect,
    ForN,
    Imply,
    Increase,
    Literal,
    Not,
    Or,
    Problem,
    TypedVar,
    When,
    load_domain,
    load_pddl,
    load_problem,
    parse_atom,
    parse_domain,
    parse_formula,
    parse_pddl,
    parse_problem,
)
from tests.data_paths import PDDL

PROBLEM_COUNTS = {"blocks": 35, "gripper": 20, "miconic-simpleadl": 30}


@pytest.mark.parametrize("name", sorted(PROBLEM_COUNTS))
def test_every_reference_file_parses(name: str) -> None:
    domain = load_domain(PDDL / name / "domain.pddl")
    problems = sorted(p for p in (PDDL / name).glob("*.pddl") if p.name != "domain.pddl")
    assert len(problems) == PROBLEM_COUNTS[name]
    for path in problems:
        problem = load_problem(path, domain)
        assert problem.domain_name == domain.name
        assert problem.init and problem.goal != TRUE
        assert isinstance(load_pddl(path), Problem)
    assert isinstance(load_pddl(PDDL / name / "domain.pddl"), Domain)


def test_blocks_domain_is_untyped_strips() -> None:
    domain = load_domain(PDDL / "blocks" / "domain.pddl")
    assert domain.name == "blocks"  # stored lower case
    assert domain.requirements == (":strips",)
    assert set(domain.actions) == {"pick-up", "put-down", "stack", "unstack"}
    stack = domain.actions["stack"]
    assert stack.params == (TypedVar("?x"), TypedVar("?y"))
    assert stack.params[0].types == (OBJECT,)
    assert stack.precondition == And((Atom("holding", ("?x",)), Atom("clear", ("?y",))))
    assert Literal(Atom("holding", ("?x",)), negated=True) in stack.effect.parts


def test_miconic_conditional_effects() -> None:
    domain = load_domain(PDDL / "miconic-simpleadl" / "domain.pddl")
    assert domain.types == {"object": (), "passenger": ("object",), "floor": ("object",)}
    stop = domain.actions["stop"]
    first = stop.effect.parts[0]
    assert isinstance(first, ForallEffect) and first.params == (TypedVar("?p", ("passenger",)),)
    assert isinstance(first.effect, When)
    assert first.effect.condition == And((Atom("boarded", ("?p",)), Atom("destin", ("?p", "?f"))))
    second = stop.effect.parts[1].effect
    assert second.condition.parts[1] == Not(Atom("served", ("?p",)))
    problem = load_problem(PDDL / "miconic-simpleadl" / "s1-0.pddl", domain)
    assert problem.objects == {"p0": "passenger", "f0": "floor", "f1": "floor"}
    assert Atom("lift-at", ("f0",)) in problem.init


ADL_DOMAIN = """
; a comment before everything
(DEFINE (DOMAIN Kitchen)  ; case-insensitive
  (:requirements :typing :adl :equality :action-costs)
  (:types cube mug - item item box - object lidded - box)
  (:constants Table - object)
  (:predicates (on ?x - item ?y) (in ?x - item ?b - box) (open ?b - box) (fits ?x - (either cube mug))
               (handempty))
  (:functions (total-cost) - number)
  (:action put
    :parameters (?x - (either cube mug) ?b - box)
    :precondition (and (not (= ?x ?b)) (imply (on ?x table) (handempty))
                       (or (open ?b) (exists (?y - item) (in ?y ?b))))
    :effect (and (in ?x ?b) (not (on ?x table))
                 (forall (?m - mug) (when (and (in ?m ?b) (forall (?c - cube) (not (in ?c ?b)))) (on ?m table)))
                 (increase (total-cost) 2)))
  (:action wait :parameters () :precondition (and) :effect (and))
  (:action noop :parameters (?x) :precondition () :effect ()))
"""

ADL_PROBLEM = """
(define (problem P1) (:domain KITCHEN)
  (:objects c1 c2 - cube m1 - mug b1 - lidded thing)
  (:init (ON c1 table) (open b1) (= (total-cost) 0))
  (:goal (and (in c1 b1) (forall (?c - cube) (imply (on ?c table) (not (open b1))))))
  (:metric minimize (total-cost)))
"""


def test_adl_features_and_action_costs() -> None:
    domain = parse_domain(ADL_DOMAIN)
    assert domain.name == "kitchen"
    assert domain.types == {
        "object": (),
        "cube": ("item",),
        "mug": ("item",),
        "item": ("object",),
        "box": ("object",),
        "lidded": ("box",),
    }
    assert domain.is_subtype("lidded", "box") and domain.is_subtype("cube", ("mug", "item"))
    assert domain.constants == {"table": "object"}
    assert domain.predicates["fits"].params == (TypedVar("?x", ("cube", "mug")),)
    assert set(domain.functions) == {"total-cost"}
    put = domain.actions["put"]
    assert put.params[0] == TypedVar("?x", ("cube", "mug"))
    not_eq, imply, disj = put.precondition.parts
    assert not_eq == Not(Equals("?x", "?b"))
    assert imply == Imply(Atom("on", ("?x", "table")), Atom("handempty"))
    assert disj.parts[1] == Exists((TypedVar("?y", ("item",)),), Atom("in", ("?y", "?b")))
    nested = put.effect.parts[2]
    assert isinstance(nested.effect, When)
    assert isinstance(nested.effect.condition.parts[1], Forall)
    assert put.effect.parts[3] == Increase("total-cost", (), 2.0)
    assert domain.actions["wait"].precondition == TRUE and domain.actions["wait"].effect == AndEffect(())
    assert domain.actions["noop"].params == (TypedVar("?x"),) and domain.actions["noop"].precondition == TRUE

    problem = parse_problem(ADL_PROBLEM, domain=domain)
    assert problem.objects == {"c1": "cube", "c2": "cube", "m1": "mug", "b1": "lidded", "thing": "object"}
    assert problem.init == frozenset({Atom("on", ("c1", "table")), Atom("open", ("b1",))})
    assert problem.init_numeric == {Atom("total-cost"): 0.0}
    assert problem.metric == ("minimize", "total-cost")
    assert isinstance(problem.goal.parts[1], Forall)
    assert parse_problem(ADL_PROBLEM) == problem  # without the domain: same model, fewer checks


def test_parse_pddl_detects_the_kind() -> None:
    assert isinstance(parse_pddl(ADL_DOMAIN), Domain)
    assert isinstance(parse_pddl(ADL_PROBLEM), Problem)


def test_formula_and_atom_fragments() -> None:
    assert parse_formula("(and (on a b) (not (open d)))") == And(
        (Atom("on", ("a", "b")), Not(Atom("open", ("d",))))
    )
    assert parse_formula("(AND)") == TRUE
    assert parse_formula("(or)") == Or(())
    assert parse_formula("(forn (2) (?x - cube) (on ?x t))") == ForN(
        2, (TypedVar("?x", ("cube",)),), Atom("on", ("?x", "t"))
    )
    assert parse_atom("(On Short_Cabinet/Drawer_Low teapot.n.01_1)") == Atom(
        "on", ("short_cabinet/drawer_low", "teapot.n.01_1")
    )
    # keywords are only keywords where the grammar expects them
    assert parse_formula("(domain and or)") == Atom("domain", ("and", "or"))


def _error(text: str, kind: str = "domain", domain: Domain | None = None) -> ParseError:
    with pytest.raises(ParseError) as info:
        if kind == "domain":
            parse_domain(text, "dom.pddl")
        elif kind == "problem":
            parse_problem(text, "prob.pddl", domain)
        else:
            parse_formula(text, "goal.pddl")
    return info.value


def _position(text: str, marker: str) -> tuple[int, int]:
    """1-based line and column of the last occurrence of ``marker`` (where the error must point)."""
    offset = text.rindex(marker)
    return text.count("\n", 0, offset) + 1, offset - (text.rfind("\n", 0, offset) + 1) + 1


HEAD = "(define (domain d) (:requirements :typing)\n(:types block)\n(:predicates (on ?x ?y - block) (clear ?x))\n"


@pytest.mark.parametrize(
    ("text", "message", "marker"),
    [
        (
            HEAD + "(:action a :parameters (?x) :precondition (onn ?x) :effect (clear ?x)))",
            "undeclared predicate 'onn'",
            "onn",
        ),
        (
            HEAD + "(:action a :parameters (?x) :precondition (on ?x) :effect (clear ?x)))",
            "takes 2 argument(s), got 1",
            "on ?x)",
        ),
        (HEAD + "(:action a :parameters (?x - ball)))", "undeclared type 'ball'", "ball"),
        (HEAD + "(:action a :parameters (?x) :effect (clear ?y)))", "unbound variable ?y", "?y"),
        (
            HEAD + "(:action a :parameters (?x) :effect (forall (?z) (clear ?x))) (:action a))",
            "duplicate action 'a'",
            "a))",
        ),
        (HEAD + "(:action a :parameters (?x ?x)))", "duplicate parameter ?x", "?x)"),
        (HEAD + "(:action a :parameters (?x) :effect (clear table)))", "unknown object 'table'", "table"),
        ("(define (domain d) (:predicates (p) (q) (p ?x)))", "duplicate predicate 'p'", "p ?x"),
        ("(define (domain d) (:types a - b b - a))", "type 'a' is its own ancestor", "a - b"),
        ("(define (domain d) (:types a - a))", "type 'a' cannot be its own parent", "a - a"),
        (
            "(define (domain d)\n  (:requirements :strips :fluents))",
            "unsupported requirement :fluents",
            ":fluents",
        ),
        (
            "(define (domain d) (:predicates (p)) (:predicates (q)))",
            "duplicate (:predicates) section",
            "(:predicates (q",
        ),
        ("(define (domain d) (:types - a))", "'-' with no names before it", "- a"),
    ],
)
def test_domain_semantic_errors(text: str, message: str, marker: str) -> None:
    err = _error(text)
    line, column = _position(text, marker)
    assert message in err.message
    assert (err.source, err.line, err.column) == ("dom.pddl", line, column)
    assert str(err).startswith(f"dom.pddl:{line}:{column}: ")


DOM = parse_domain(HEAD + "(:action a :parameters (?x) :effect (clear ?x)))")


@pytest.mark.parametrize(
    ("text", "message", "marker"),
    [
        (
            "(define (problem p) (:domain d) (:objects a - block) (:init (on a z)) (:goal (and)))",
            "unknown object 'z'",
            "z))",
        ),
        (
            "(define (problem p) (:domain d) (:objects a - ball) (:goal (and)))",
            "undeclared type 'ball'",
            "ball",
        ),
        ("(define (problem p) (:domain d)\n(:objects a a) (:goal (and)))", "duplicate object a", "a)"),
        (
            "(define (problem p) (:domain d) (:init (held a)) (:goal (and)))",
            "undeclared predicate 'held'",
            "held",
        ),
        ("(define (problem p) (:domain d) (:objects a) (:goal (clear ?x)))", "unbound variable ?x", "?x"),
        ("(define (problem p) (:domain e) (:goal (and)))", "problem is for domain 'e', not 'd'", "e)"),
        (
            "(define (problem p) (:domain d) (:objects a) (:init (clear a) (not (clear a))) (:goal (and)))",
            "(clear a) is both true and false in :init",
            "(not (clear",
        ),
        (
            "(define (problem p) (:domain d) (:objects a) (:init (not (held a))) (:goal (and)))",
            "undeclared predicate 'held'",
            "held",
        ),
        ("(define (problem p) (:domain d) (:objects a))", "problem has no (:goal", "(define"),
    ],
)
def test_problem_semantic_errors(text: str, message: str, marker: str) -> None:
    err = _error(text, "problem", DOM)
    line, column = _position(text, marker)
    assert message in err.message
    assert (err.line, err.column) == (line, column)


def test_negative_init_literals_are_redundant_under_the_closed_world() -> None:
    # Fast Downward accepts (not (p)) in :init; it states what the closed world already says
    text = (
        "(define (problem p) (:domain d) (:objects a b) (:init (clear a) (not (clear b))) (:goal (clear b)))"
    )
    problem = parse_problem(text, domain=DOM)
    assert problem.init == frozenset({Atom("clear", ("a",))})


def test_syntax_errors_are_readable() -> None:
    eof = _error("(define (domain d)\n  (:predicates (p))")
    assert (eof.line, eof.column) == (2, 20)
    assert "end of file" in eof.message and '")"' in eof.expected
    section = _error("(define (domain d)\n  (:predicats (p)))")
    assert "':predicats'" in section.message and (section.line, section.column) == (2, 4)
    assert '":predicates"' in section.expected and '":action"' in section.expected
    token = _error("(and (on a b) (or (p) 7))", "formula")
    assert (token.line, token.column) == (1, 23)
    assert '"("' in token.expected and not any("PAR" in e for e in token.expected)
    assert "expected" in str(token) and "LPAR" not in str(token)
    for empty in ("", "   \n; nothing but a comment\n"):
        err = _error(empty)
        assert (err.message, err.line, err.column) == ("empty file", 1, 1)


def test_load_errors_name_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.pddl"
    bad.write_text(
        "(define (domain d)\n (:predicates (p ?x))\n (:action a :parameters (?x) :precondition (p ?y)))\n"
    )
    with pytest.raises(ParseError, match=r"bad\.pddl:3:47: unbound variable \?y"):
        load_domain(bad)
    with pytest.raises(ParseError, match="cannot read file"):
        load_pddl(tmp_path / "missing.pddl")


def test_names_may_start_with_a_digit_numbers_stay_numbers() -> None:
    # Fast Downward reads (:objects 1 2 3); a number is still read where a number is expected
    domain = parse_domain(
        "(define (domain n) (:requirements :action-costs) (:predicates (p ?x) (n ?x ?y))"
        " (:functions (d ?x ?y) (total-cost))"
        " (:action go :parameters (?x ?y) :precondition (and (p ?x) (n ?x ?y))"
        "  :effect (and (p ?y) (not (p ?x)) (increase (total-cost) (d ?x ?y)))))"
    )
    problem = parse_problem(
        "(define (problem q) (:domain n) (:objects 1 2 3x)"
        " (:init (p 1) (n 1 2) (n 2 3x) (= (d 1 2) 10) (= (d 2 3x) 2.5) (= (total-cost) 0))"
        " (:goal (p 3x)) (:metric minimize (total-cost)))",
        domain=domain,
    )
    assert set(problem.objects) == {"1", "2", "3x"}
    assert Atom("n", ("1", "2")) in problem.init
    assert problem.init_numeric[Atom("d", ("1", "2"))] == 10.0
    assert problem.init_numeric[Atom("d", ("2", "3x"))] == 2.5
