"""PDDL writer: round trips (reference files and hypothesis-built models) and Fast Downward acceptance."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gsr.pddl import (
    OBJECT,
    Action,
    And,
    AndEffect,
    Atom,
    Domain,
    Equals,
    Exists,
    Forall,
    ForallEffect,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Increase,
    Literal,
    Not,
    Or,
    Predicate,
    Problem,
    TypedVar,
    When,
    load_domain,
    load_problem,
    parse_domain,
    parse_formula,
    parse_problem,
    write_domain,
    write_effect,
    write_formula,
    write_problem,
)
from tests.data_paths import PDDL

KEYWORDS = {
    "and",
    "or",
    "not",
    "imply",
    "exists",
    "forall",
    "forn",
    "forpairs",
    "fornpairs",
    "when",
    "increase",
}


@pytest.mark.parametrize("name", ["blocks", "gripper", "miconic-simpleadl"])
def test_reference_files_round_trip(name: str) -> None:
    domain = load_domain(PDDL / name / "domain.pddl")
    assert parse_domain(write_domain(domain)) == domain
    for path in sorted((PDDL / name).glob("*.pddl")):
        if path.name != "domain.pddl":
            problem = load_problem(path, domain)
            text = write_problem(problem)
            assert parse_problem(text, domain=domain) == problem
            assert write_problem(parse_problem(text)) == text  # deterministic output


def test_long_formulas_are_indented() -> None:
    goal = And(tuple(Atom("on", (f"block-{i}", f"block-{i + 1}")) for i in range(12)))
    text = write_formula(goal)
    lines = text.splitlines()
    assert lines[0] == "(and" and all(line.startswith("  (on block-") for line in lines[1:])
    assert parse_formula(text) == goal
    assert write_formula(Not(Equals("?x", "?y"))) == "(not (= ?x ?y))"
    effect = AndEffect((Literal(Atom("p", ("?x",)), negated=True), Increase("total-cost", (), 3.0)))
    assert write_effect(effect) == "(and (not (p ?x)) (increase (total-cost) 3))"


# ----------------------------------------------------------------- Fast Downward


def _fast_downward() -> Path | None:
    try:
        import up_fast_downward
    except ImportError:
        return None
    driver = Path(up_fast_downward.__file__).parent / "downward" / "fast-downward.py"
    return driver if driver.is_file() else None


COST_DOMAIN = """(define (domain lift) (:requirements :typing :action-costs)
  (:types box)
  (:predicates (at-top ?b - box) (at-bottom ?b - box))
  (:functions (total-cost) - number)
  (:action raise :parameters (?b - box) :precondition (at-bottom ?b)
    :effect (and (at-top ?b) (not (at-bottom ?b)) (increase (total-cost) 3))))"""
COST_PROBLEM = """(define (problem two) (:domain lift) (:objects a b - box)
  (:init (at-bottom a) (at-bottom b) (= (total-cost) 0))
  (:goal (and (at-top a) (at-top b))) (:metric minimize (total-cost)))"""


@pytest.mark.parametrize(
    ("name", "problem", "search"),
    [
        ("blocks", "probBLOCKS-6-0.pddl", ["--alias", "lama-first"]),
        ("gripper", "prob01.pddl", ["--alias", "lama-first"]),
        ("miconic-simpleadl", "s4-0.pddl", ["--search", "astar(blind())"]),
        ("action-costs", "", ["--search", "astar(blind())"]),
    ],
)
def test_fast_downward_accepts_written_files(
    tmp_path: Path, name: str, problem: str, search: list[str]
) -> None:
    driver = _fast_downward()
    if driver is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    if name == "action-costs":
        domain = parse_domain(COST_DOMAIN)
        task = parse_problem(COST_PROBLEM, domain=domain)
    else:
        domain = load_domain(PDDL / name / "domain.pddl")
        task = load_problem(PDDL / name / problem, domain)
    alias, search = (search, []) if search[0] == "--alias" else ([], search)  # driver options precede files
    (tmp_path / "domain.pddl").write_text(write_domain(domain))
    (tmp_path / "problem.pddl").write_text(write_problem(task))
    run = subprocess.run(
        [sys.executable, str(driver), *alias, "domain.pddl", "problem.pddl", *search],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    plan = (tmp_path / "sas_plan").read_text()
    assert plan.strip().splitlines()[0].startswith("(")
    if name == "action-costs":
        assert "; cost = 6" in plan


# --------------------------------------------------------------- hypothesis models

names = st.from_regex(r"[a-z][a-z0-9_\-./]{0,5}", fullmatch=True).filter(
    lambda s: s not in KEYWORDS | {OBJECT}
)


@st.composite
def types_and_hierarchy(draw: st.DrawFn) -> dict[str, tuple[str, ...]]:
    """A type hierarchy: each type's parents are object, earlier types, or an either of them."""
    declared = draw(st.lists(names, max_size=4, unique=True))
    types: dict[str, tuple[str, ...]] = {OBJECT: ()}
    for name in declared:
        earlier = [t for t in types if t != OBJECT]
        parents = draw(st.lists(st.sampled_from([OBJECT, *earlier]), min_size=1, max_size=2, unique=True))
        types[name] = tuple(parents)
    return types


def type_specs(types: dict[str, tuple[str, ...]]) -> st.SearchStrategy[tuple[str, ...]]:
    return st.lists(st.sampled_from(sorted(types)), min_size=1, max_size=2, unique=True).map(tuple)


@st.composite
def formulas(
    draw: st.DrawFn,
    predicates: list[Predicate],
    terms: list[str],
    types,
    depth: int = 3,
    counting: bool = False,
) -> Formula:
    """A random goal description over ``predicates``; arguments from ``terms`` and bound variables."""
    kinds = ["atom", "atom", "equals"]
    if depth > 0:
        kinds += ["not", "and", "or", "imply", "exists", "forall"] + (
            ["forn", "forpairs"] if counting else []
        )
    kind = draw(st.sampled_from(kinds))
    sub = lambda extra=(): formulas(predicates, [*terms, *extra], types, depth - 1, counting)  # noqa: E731
    if kind == "atom":
        p = draw(st.sampled_from(predicates))
        return Atom(p.name, tuple(draw(st.sampled_from(terms)) for _ in range(p.arity)))
    if kind == "equals":
        return Equals(draw(st.sampled_from(terms)), draw(st.sampled_from(terms)))
    if kind == "not":
        return Not(draw(sub()))
    if kind in ("and", "or"):
        parts = tuple(draw(st.lists(sub(), max_size=3)))
        return And(parts) if kind == "and" else Or(parts)
    if kind == "imply":
        return Imply(draw(sub()), draw(sub()))
    var = TypedVar(f"?v{depth}", draw(type_specs(types)))
    if kind == "forpairs":
        other = TypedVar(f"?w{depth}", draw(type_specs(types)))
        return ForPairs((var,), (other,), draw(sub([var.name, other.name])))
    body = draw(sub([var.name]))
    if kind == "forn":
        return ForN(draw(st.integers(0, 4)), (var,), body)
    return Exists((var,), body) if kind == "exists" else Forall((var,), body)


@st.composite
def effects(draw: st.DrawFn, predicates: list[Predicate], terms: list[str], types, depth: int = 2) -> object:
    kinds = ["literal", "literal", "increase"] + (["and", "forall", "when"] if depth > 0 else [])
    kind = draw(st.sampled_from(kinds))
    if kind == "literal":
        p = draw(st.sampled_from(predicates))
        atom = Atom(p.name, tuple(draw(st.sampled_from(terms)) for _ in range(p.arity)))
        return Literal(atom, draw(st.booleans()))
    if kind == "increase":
        return Increase("total-cost", (), float(draw(st.integers(0, 50))))
    if kind == "and":
        return AndEffect(tuple(draw(st.lists(effects(predicates, terms, types, depth - 1), max_size=3))))
    if kind == "when":
        return When(
            draw(formulas(predicates, terms, types, 2)), draw(effects(predicates, terms, types, depth - 1))
        )
    var = TypedVar(f"?e{depth}", draw(type_specs(types)))
    return ForallEffect((var,), draw(effects(predicates, [*terms, var.name], types, depth - 1)))


def typed_params(types: dict[str, tuple[str, ...]], prefix: str, min_size: int = 0) -> st.SearchStrategy:
    return st.lists(type_specs(types), min_size=min_size, max_size=3).map(
        lambda specs: tuple(TypedVar(f"?{prefix}{i}", spec) for i, spec in enumerate(specs))
    )


@st.composite
def domains(draw: st.DrawFn) -> Domain:
    """A random, consistent domain (every name used is declared)."""
    types = draw(types_and_hierarchy())
    constant_names = draw(st.lists(names, max_size=3, unique=True))
    constants = {c: draw(st.sampled_from(sorted(types))) for c in constant_names}
    predicate_names = draw(st.lists(names, min_size=1, max_size=4, unique=True))
    predicates = {n: Predicate(n, draw(typed_params(types, "p"))) for n in predicate_names}
    actions = {}
    for name in draw(st.lists(names, max_size=3, unique=True)):
        params = draw(typed_params(types, "x", min_size=1))
        terms = [p.name for p in params] + list(constants)
        pre = draw(formulas(list(predicates.values()), terms, types))
        actions[name] = Action(name, params, pre, draw(effects(list(predicates.values()), terms, types)))
    requirements = tuple(
        draw(st.lists(st.sampled_from([":strips", ":typing", ":adl", ":action-costs"]), unique=True))
    )
    return Domain(
        name=draw(names),
        requirements=requirements,
        types=types,
        constants=constants,
        predicates=predicates,
        functions={"total-cost": Predicate("total-cost")},
        actions=actions,
    )


@st.composite
def problems(draw: st.DrawFn, domain: Domain) -> Problem:
    types = sorted(domain.types)
    object_names = draw(
        st.lists(names.filter(lambda n: n not in domain.constants), min_size=1, max_size=5, unique=True)
    )
    objects = {o: draw(st.sampled_from(types)) for o in object_names}
    terms = object_names + list(domain.constants)
    predicates = list(domain.predicates.values())
    init = set()
    for _ in range(draw(st.integers(0, 6))):
        p = draw(st.sampled_from(predicates))
        init.add(Atom(p.name, tuple(draw(st.sampled_from(terms)) for _ in range(p.arity))))
    numeric = {Atom("total-cost"): float(draw(st.integers(0, 9)))} if draw(st.booleans()) else {}
    return Problem(
        name=draw(names),
        domain_name=domain.name,
        objects=objects,
        init=frozenset(init),
        goal=draw(formulas(predicates, terms, domain.types)),
        requirements=tuple(draw(st.lists(st.sampled_from([":strips", ":typing"]), unique=True))),
        init_numeric=numeric,
        metric=("minimize", "total-cost") if numeric else None,
    )


SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(st.data())
def test_random_formulas_round_trip(data: st.DataObject) -> None:
    predicates = [Predicate(n, tuple(TypedVar(f"?a{i}") for i in range(k))) for n, k in data.draw(
        st.lists(st.tuples(names, st.integers(0, 3)), min_size=1, max_size=4, unique_by=lambda t: t[0])
    )]  # fmt: skip
    terms = data.draw(st.lists(names | names.map(lambda n: "?" + n), min_size=1, max_size=4))
    types = {OBJECT: (), "cube": (OBJECT,), "mug": (OBJECT,)}
    formula = data.draw(formulas(predicates, terms, types, depth=4, counting=True))
    assert parse_formula(write_formula(formula)) == formula


@SETTINGS
@given(st.data())
def test_random_domains_and_problems_round_trip(data: st.DataObject) -> None:
    domain = data.draw(domains())
    text = write_domain(domain)
    parsed = parse_domain(text)
    assert parsed == domain, text
    problem = data.draw(problems(domain))
    problem_text = write_problem(problem)
    assert parse_problem(problem_text, domain=parsed) == problem, problem_text
