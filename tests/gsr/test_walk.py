"""The one formula walker: structure, fold/map, free variables (forn/forpairs too), negation, NNF, DNF."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gsr.plan.grounding.simplify as simplify
import gsr.semantics as semantics
from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
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
    nnf,
    subformulas,
    to_dnf,
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


def _is_nnf(f) -> bool:
    """No ``imply``; every ``not`` directly above an atom, an equality or a counting quantifier (kept
    whole: its body is not rewritten)."""
    if isinstance(f, (ForN, ForPairs, Atom, Equals)):
        return True
    if isinstance(f, Not):
        return isinstance(f.formula, (Atom, Equals, ForN, ForPairs))
    return not isinstance(f, Imply) and all(_is_nnf(c) for c in children(f))


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None, max_examples=100)
@given(FORMULAS)
def test_nnf_is_equivalent_and_normal(f) -> None:
    positive, negative = nnf(f), nnf(f, negated=True)
    assert _is_nnf(positive) and _is_nnf(negative)
    assert free_variables(positive) == free_variables(f) == free_variables(negative)
    closed = f
    for name in sorted(free_variables(f)):
        closed = Exists((TypedVar(name, ("thing",)),), closed)
    for state in itertools.islice(_states(), 4):
        truth = holds(DOMAIN, closed, state)
        assert holds(DOMAIN, nnf(closed), state) is truth
        assert holds(DOMAIN, nnf(closed, negated=True), state) is (not truth)


GROUND = st.recursive(
    st.builds(lambda o: Atom("p", (o,)), st.sampled_from(["a", "b", "c"])) | st.sampled_from([TRUE, FALSE]),
    lambda inner: st.one_of(
        st.builds(Not, inner),
        st.builds(And, st.lists(inner, max_size=3).map(tuple)),
        st.builds(Or, st.lists(inner, max_size=3).map(tuple)),
        st.builds(Imply, inner, inner),
    ),
    max_leaves=8,
)


def _dnf_holds(dnf, true: set[str]) -> bool:
    return any(all((a.args[0] in true) is positive for a, positive in conj) for conj in dnf)


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None, max_examples=100)
@given(GROUND)
def test_dnf_of_a_ground_nnf_is_equivalent_without_contradictions(f) -> None:
    dnf = to_dnf(_fold_constants(nnf(f)))
    assert len(set(dnf)) == len(dnf)  # each conjunction once
    assert all(not any((a, not p) in conj for a, p in conj) for conj in dnf)  # none contradictory
    for bits in range(8):
        true = {o for i, o in enumerate("abc") if bits >> i & 1}
        state = State(frozenset(Atom("p", (o,)) for o in true), OBJECTS)
        assert _dnf_holds(dnf, true) is holds(DOMAIN, f, state)


def _fold_constants(f):
    """``not TRUE`` / ``not FALSE`` (which NNF keeps as negated empty conjunctions) as FALSE / TRUE."""
    if isinstance(f, Not) and f.formula in (TRUE, FALSE):
        return FALSE if f.formula == TRUE else TRUE
    if isinstance(f, (And, Or)):
        return type(f)(tuple(_fold_constants(p) for p in f.parts))
    return f


def test_dnf_refuses_what_is_not_ground_nnf_and_too_many_disjuncts() -> None:
    with pytest.raises(GSRError, match="not in ground NNF"):
        to_dnf(Imply(Atom("p", ("a",)), Atom("p", ("b",))))
    wide = And(tuple(Or((Atom("p", (f"a{i}",)), Atom("q", (f"a{i}", "b")))) for i in range(9)))
    assert len(to_dnf(wide)) == 2**9
    with pytest.raises(GSRError, match="too disjunctive"):
        to_dnf(wide, limit=256)
