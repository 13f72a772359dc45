"""The one formula walker: structure, fold/map, free variables (forn/forpairs too), negation."""

from __future__ import annotations

import itertools

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gsr.plan.grounding.simplify as simplify
import gsr.semantics as semantics
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
from gsr.pddl.walk import (
    atoms,
    bound_variables,
    children,
    fold,
    free_variables,
    map_atoms,
    map_formula,
    negate,
    subformulas,
    with_children,
)
from gsr.semantics import holds
from gsr.state import State

DOMAIN = parse_domain(
    "(define (domain w) (:requirements :adl) (:types thing) (:predicates (p ?x - thing) (q ?x ?y - thing)))"
)
OBJECTS = {"a": "thing", "b": "thing", "c": "thing"}
X, Y = TypedVar("?x", ("thing",)), TypedVar("?y", ("thing",))
TERMS = st.sampled_from(["a", "b", "?x", "?y"])
LEAVES = st.one_of(
    st.builds(lambda t: Atom("p", (t,)), TERMS),
    st.builds(lambda s, t: Atom("q", (s, t)), TERMS, TERMS),
    st.builds(Equals, TERMS, TERMS),
)


def _extend(inner):
    parts = st.lists(inner, max_size=3).map(tuple)
    return st.one_of(
        st.builds(Not, inner),
        st.builds(And, parts),
        st.builds(Or, parts),
        st.builds(Imply, inner, inner),
        st.builds(Exists, st.sampled_from([(X,), (Y,), (X, Y)]), inner),
        st.builds(Forall, st.sampled_from([(X,), (Y,), (X, Y)]), inner),
        st.builds(ForN, st.integers(1, 2), st.just((X,)), inner),
        st.builds(ForPairs, st.just((X,)), st.just((Y,)), inner),
    )


FORMULAS = st.recursive(LEAVES, _extend, max_leaves=8)


def test_free_variables_is_one_function_and_knows_bddl_quantifiers() -> None:
    assert simplify.free_variables is semantics.free_variables is free_variables
    f = parse_formula("(forn (2) (?x - thing) (and (p ?x) (q ?x ?z)))")
    assert free_variables(f) == {"?z"}
    pairs = ForPairs((X,), (Y,), And((Atom("q", ("?x", "?y")), Atom("p", ("?w",)))))
    assert free_variables(pairs) == {"?w"} and bound_variables(pairs) == (X, Y)
    assert free_variables(Imply(Equals("?a", "b"), Exists((X,), Atom("q", ("?x", "?b"))))) == {"?a", "?b"}


def test_walks_visit_every_node_in_order() -> None:
    f = parse_formula("(and (p a) (not (q a ?x)) (exists (?y - thing) (or (p ?y) (= ?y b))))")
    assert [type(n).__name__ for n in subformulas(f)] == [
        "And", "Atom", "Not", "Atom", "Exists", "Or", "Atom", "Equals",
    ]  # fmt: skip
    assert [str(a) for a in atoms(f)] == ["(p a)", "(q a ?x)", "(p ?y)"]
    assert fold(f, lambda node, inner: 1 + sum(inner)) == 8
    renamed = map_atoms(f, lambda a: Atom(a.predicate, tuple("c" if t == "a" else t for t in a.args)))
    assert [str(a) for a in atoms(renamed)] == ["(p c)", "(q c ?x)", "(p ?y)"]
    assert map_formula(f, lambda node: node) is f  # nothing changed: nothing rebuilt


def _states():
    facts = [Atom("p", (o,)) for o in OBJECTS] + [Atom("q", (s, t)) for s in OBJECTS for t in OBJECTS]
    for mask in (0b0, 0b101, 0b1101001, 0b111111111111):
        yield State(frozenset(f for i, f in enumerate(facts) if mask >> i & 1), OBJECTS)


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None, max_examples=150)
@given(FORMULAS)
def test_structure_and_negation_properties(f) -> None:
    assert map_formula(f, lambda node: node) == f
    assert sum(1 for _ in subformulas(f)) == fold(f, lambda node, inner: 1 + sum(inner))
    assert all(with_children(n, children(n)) is n for n in subformulas(f))
    assert free_variables(negate(f)) == free_variables(f)
    closed = f
    for name in sorted(free_variables(f)):  # bind what is free, so the formula can be evaluated
        closed = Exists((TypedVar(name, ("thing",)),), closed)
    for state in itertools.islice(_states(), 4):
        assert holds(DOMAIN, negate(closed), state) is (not holds(DOMAIN, closed, state))
