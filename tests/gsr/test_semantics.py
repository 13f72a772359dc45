"""Closed-world semantics: compiled formula evaluation against a naive reference, effects, costs."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gsr.errors import GSRError
from gsr.pddl.model import (
    And,
    Atom,
    Equals,
    Exists,
    Forall,
    ForN,
    ForPairs,
    Imply,
    Not,
    Or,
    TypedVar,
)
from gsr.pddl.parser import parse_domain, parse_formula
from gsr.semantics import (
    action_cost,
    applicable,
    apply,
    fact_index,
    goal_holds,
    ground_effects,
    holds,
)
from gsr.state import State

DOMAIN = """
(define (domain shop)
  (:requirements :adl :typing :action-costs)
  (:types cube mug - item  item box - object  lidded - box)
  (:predicates (on ?x - item ?y - object) (in ?x - item ?b - box) (open ?b - box) (red ?x - object)
               (holding ?x - item) (marked ?x - object))
  (:functions (total-cost))
  (:action pack
    :parameters (?x - item ?b - box)
    :precondition (and (holding ?x) (imply (red ?b) (open ?b)) (not (= ?x ?b)))
    :effect (and (not (holding ?x)) (in ?x ?b)
                 (when (red ?x) (marked ?b))
                 (forall (?y - cube) (when (in ?y ?b) (not (red ?y))))
                 (increase (total-cost) 3)))
  (:action toggle
    :parameters (?b - box)
    :precondition (or (open ?b) (red ?b))
    :effect (and (when (open ?b) (not (open ?b))) (when (not (open ?b)) (open ?b))))
  (:action touch
    :parameters (?b - box)
    :precondition ()
    :effect (and (not (marked ?b)) (marked ?b)))
)
"""

OBJECTS = {"c1": "cube", "c2": "cube", "m1": "mug", "b1": "box", "b2": "lidded"}


@pytest.fixture(scope="module")
def domain():
    return parse_domain(DOMAIN)


def state(*facts: str) -> State:
    atoms = set()
    for f in facts:
        p, *args = f.split()
        atoms.add(Atom(p, tuple(args)))
    return State(frozenset(atoms), dict(OBJECTS))


def test_typed_quantifiers_range_over_subtypes(domain) -> None:
    s = state("red c1", "red c2", "red m1")
    assert holds(domain, parse_formula("(forall (?x - item) (red ?x))"), s)
    assert holds(domain, parse_formula("(forall (?x - cube) (red ?x))"), s)
    assert not holds(domain, parse_formula("(forall (?x - object) (red ?x))"), s)  # boxes are not red
    assert holds(domain, parse_formula("(exists (?b - box) (= ?b b2))"), s)  # lidded is a box
    assert not holds(domain, parse_formula("(exists (?b - lidded) (= ?b b1))"), s)
    assert holds(domain, parse_formula("(forall (?x - (either cube mug)) (red ?x))"), s)


def test_connectives_equality_and_bindings(domain) -> None:
    s = state("on c1 b1", "open b1")
    f = parse_formula("(and (on ?x ?y) (imply (red ?y) (open ?y)) (not (= ?x ?y)))")
    assert holds(domain, f, s, {"?x": "c1", "?y": "b1"})
    assert not holds(domain, f, s, {"?x": "c1", "?y": "b2"})
    assert holds(domain, parse_formula("(or (on c2 b1) (open b1))"), s)
    assert holds(domain, And(()), s) and not holds(domain, Or(()), s)
    with pytest.raises(GSRError, match="free variable"):
        holds(domain, parse_formula("(on ?x b1)"), s)


def test_nested_quantifiers(domain) -> None:
    s = state("on c1 b1", "on c2 b2", "on m1 b1")
    every_box_has = parse_formula("(forall (?b - box) (exists (?x - item) (on ?x ?b)))")
    assert holds(domain, every_box_has, s)
    assert not holds(domain, every_box_has, state("on c1 b1"))
    only_cubes_on_b2 = parse_formula("(forall (?x - item) (imply (on ?x b2) (exists (?c - cube) (= ?c ?x))))")
    assert holds(domain, only_cubes_on_b2, s)
    assert not holds(domain, only_cubes_on_b2, state("on m1 b2"))


def test_forn_and_forpairs(domain) -> None:
    s = state("on c1 b1", "on c2 b2", "on m1 b1")
    x, b = TypedVar("?x", ("item",)), TypedVar("?b", ("box",))
    assert holds(domain, ForN(2, (x,), Atom("on", ("?x", "b1"))), s)
    assert not holds(domain, ForN(3, (x,), Atom("on", ("?x", "b1"))), s)
    cube = TypedVar("?c", ("cube",))
    pairs = ForPairs((cube,), (b,), Atom("on", ("?c", "?b")))
    assert holds(domain, pairs, s)  # c1-b1, c2-b2
    assert not holds(domain, pairs, state("on c1 b1", "on c2 b1"))  # both cubes want b1


def test_effects_when_forall_and_cost(domain) -> None:
    s = state("holding c1", "red c1", "in c2 b1", "red c2", "red m1")
    add, delete = ground_effects(domain, "pack", ("c1", "b1"), s)
    assert Atom("in", ("c1", "b1")) in add and Atom("marked", ("b1",)) in add
    # forall/when is evaluated in the state BEFORE the action: c1 is not yet in b1, so only c2 loses red
    assert Atom("red", ("c2",)) in delete and Atom("red", ("c1",)) not in delete
    assert Atom("holding", ("c1",)) in delete
    assert action_cost(domain, "pack", ("c1", "b1"), s) == 3.0
    after = apply(domain, s, "pack", ("c1", "b1"))
    assert (
        Atom("red", ("m1",)) in after and Atom("red", ("c1",)) in after and Atom("red", ("c2",)) not in after
    )


def test_conditional_toggle_uses_the_old_state(domain) -> None:
    opened = apply(domain, state("red b1"), "toggle", ("b1",))
    assert Atom("open", ("b1",)) in opened
    closed = apply(domain, opened, "toggle", ("b1",))
    assert Atom("open", ("b1",)) not in closed


def test_add_and_delete_of_the_same_atom_ends_true(domain) -> None:
    s = state("marked b1")
    assert Atom("marked", ("b1",)) in apply(domain, s, "touch", ("b1",))
    add, delete = ground_effects(domain, "touch", ("b1",), s)
    assert Atom("marked", ("b1",)) in add and Atom("marked", ("b1",)) not in delete


def test_not_applicable_and_unknown(domain) -> None:
    s = state("red b1")
    assert not applicable(domain, s, "pack", ("c1", "b1"))
    assert not applicable(domain, s, "nope", ())
    with pytest.raises(GSRError, match="not applicable"):
        apply(domain, s, "pack", ("c1", "b1"))
    with pytest.raises(GSRError, match="unknown action"):
        ground_effects(domain, "nope", (), s)
    assert goal_holds(domain, parse_formula("(red b1)"), s)


def test_successor_keeps_the_fact_index_consistent(domain) -> None:
    s = state("holding c1", "red c1", "in c2 b1", "red c2", "on m1 b2")
    fact_index(s)  # built on the parent: the child updates it incrementally
    after = apply(domain, s, "pack", ("c1", "b1"))
    incremental = {k: v for k, v in fact_index(after).items() if v}
    fresh = {k: v for k, v in fact_index(State(after.atoms, after.objects)).items() if v}
    assert {k: set(v) for k, v in incremental.items()} == {k: set(v) for k, v in fresh.items()}


# ------------------------------------------------------------ compiled vs naive reference


def naive(f, facts: set, objects: dict, domain, env: dict) -> bool:
    """Reference evaluator: substitute and walk, quantifiers over all typed objects."""

    def term(t: str) -> str:
        return env.get(t, t)

    def typed(params):
        return itertools.product(
            *([o for o, t in objects.items() if domain.is_subtype(t, p.types)] for p in params)
        )

    if isinstance(f, Atom):
        return (f.predicate, *map(term, f.args)) in facts
    if isinstance(f, Equals):
        return term(f.left) == term(f.right)
    if isinstance(f, Not):
        return not naive(f.formula, facts, objects, domain, env)
    if isinstance(f, And):
        return all(naive(p, facts, objects, domain, env) for p in f.parts)
    if isinstance(f, Or):
        return any(naive(p, facts, objects, domain, env) for p in f.parts)
    if isinstance(f, Imply):
        return not naive(f.condition, facts, objects, domain, env) or naive(
            f.then, facts, objects, domain, env
        )
    names = [p.name for p in f.params]
    results = (
        naive(f.body, facts, objects, domain, {**env, **dict(zip(names, combo, strict=True))})
        for combo in typed(f.params)
    )
    return any(results) if isinstance(f, Exists) else all(results)


VARS = ("?x", "?y")
TERMS = (*VARS, "c1", "b1")


@st.composite
def formulas(draw, depth: int = 3):
    kind = draw(
        st.sampled_from(
            ["atom", "atom", "eq", "not", "and", "or", "imply", "exists", "forall"][: 3 if depth == 0 else 9]
        )
    )
    if kind == "atom":
        pred = draw(st.sampled_from(["on", "red", "open"]))
        arity = 2 if pred == "on" else 1
        return Atom(pred, tuple(draw(st.sampled_from(TERMS)) for _ in range(arity)))
    if kind == "eq":
        return Equals(draw(st.sampled_from(TERMS)), draw(st.sampled_from(TERMS)))
    if kind == "not":
        return Not(draw(formulas(depth - 1)))
    if kind in ("and", "or"):
        parts = tuple(draw(st.lists(formulas(depth - 1), min_size=0, max_size=3)))
        return And(parts) if kind == "and" else Or(parts)
    if kind == "imply":
        return Imply(draw(formulas(depth - 1)), draw(formulas(depth - 1)))
    var = draw(st.sampled_from(VARS))
    types = draw(st.sampled_from([("item",), ("box",), ("object",), ("cube", "lidded")]))
    body = draw(formulas(depth - 1))
    return (Exists if kind == "exists" else Forall)((TypedVar(var, types),), body)


FACTS = [("on", a, b) for a in OBJECTS for b in OBJECTS] + [(p, a) for p in ("red", "open") for a in OBJECTS]


@settings(max_examples=300, deadline=None)
@given(
    f=formulas(),
    facts=st.sets(st.sampled_from(FACTS), max_size=12),
    x=st.sampled_from(list(OBJECTS)),
    y=st.sampled_from(list(OBJECTS)),
)
def test_compiled_evaluation_matches_naive_reference(domain, f, facts, x, y) -> None:
    s = State(frozenset(Atom(p, tuple(a)) for p, *a in facts), dict(OBJECTS))
    env = {"?x": x, "?y": y}
    assert holds(domain, f, s, env) == naive(f, set(facts), OBJECTS, domain, env)
