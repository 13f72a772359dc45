"""The step checker: every reason kind, explanations of quantified preconditions, repair hints."""

from __future__ import annotations

import json

import pytest

from gsr.check import check_step
from gsr.diagnosis import ReasonKind
from gsr.facts import state_from_graph
from gsr.pddl.model import Atom
from gsr.pddl.parser import load_domain, load_problem, parse_domain, parse_formula
from gsr.resources import load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.state import State, initial_state
from gsr.step import Step
from gsr.validate import explain_goal
from tests.data_paths import PDDL


@pytest.fixture(scope="module")
def blocks():
    domain = load_domain(PDDL / "blocks" / "domain.pddl")
    problem = load_problem(PDDL / "blocks" / "probBLOCKS-4-0.pddl", domain)
    return domain, initial_state(domain, problem)


@pytest.fixture(scope="module")
def tabletop():
    domain = load_builtin_domain("tabletop")
    graph = SceneGraph(
        nodes=(
            Node(id="table", category="table"),
            Node(id="red_box", category="box", attributes={"color": "red"}),
            Node(id="blue_box", category="box", attributes={"color": "blue"}),
            Node(id="blue_cube1", category="cube", attributes={"color": "blue"}),
            Node(id="red_cube1", category="cube", attributes={"color": "red"}),
            Node(id="short_cabinet", category="cabinet"),
            Node(
                id="short_cabinet/drawer_high",
                category="drawer",
                parent="short_cabinet",
                attributes={"level": 2},
                states=("open",),
            ),
            Node(
                id="short_cabinet/drawer_low",
                category="drawer",
                parent="short_cabinet",
                attributes={"level": 1},
            ),
        ),
        edges=(
            Edge(source="red_box", relation="on", target="table"),
            Edge(source="blue_box", relation="on", target="table"),
            Edge(source="blue_cube1", relation="on", target="red_box"),
            Edge(source="red_cube1", relation="on", target="table"),
            Edge(source="short_cabinet", relation="on", target="table"),
        ),
    )
    return domain, state_from_graph(graph, domain)


def test_valid_step_carries_the_transition(blocks) -> None:
    domain, state = blocks
    d = check_step(domain, state, Step("pick-up", ("a",)))
    assert d.ok and d.reasons == () and d.message == "(pick-up a): ok" and d.cost == 1.0
    assert d.add == {Atom("holding", ("a",))}
    assert d.delete == {Atom("ontable", ("a",)), Atom("clear", ("a",)), Atom("handempty")}
    assert Atom("holding", ("a",)) in d.next_state and Atom("handempty") not in d.next_state
    json.dumps(d.to_dict())


def test_unknown_action_suggests_close_names(blocks) -> None:
    domain, state = blocks
    d = check_step(domain, state, Step("pickup", ("a",)))
    assert not d.ok and [r.kind for r in d.reasons] == [ReasonKind.UNKNOWN_ACTION]
    assert d.hints[0] == "did you mean pick-up?" and d.next_state is None


def test_wrong_arity(blocks) -> None:
    domain, state = blocks
    d = check_step(domain, state, Step("stack", ("a",)))
    assert [r.kind for r in d.reasons] == [ReasonKind.WRONG_ARITY]
    assert "stack takes 2 argument(s) (stack ?x ?y), got 1" in d.message


def test_unknown_object_suggests_close_names(tabletop) -> None:
    domain, state = tabletop
    d = check_step(domain, state, Step("pick", ("red_cube", "table")))
    assert [r.kind for r in d.reasons] == [ReasonKind.UNKNOWN_OBJECT]
    assert d.reasons[0].bindings == (("?o", "red_cube"),)
    assert "red_cube1" in d.hints[0]


def test_type_mismatch_names_fitting_objects() -> None:
    domain = parse_domain(
        "(define (domain t) (:types cube box) (:predicates (in ?c - cube ?b - box))"
        " (:action put :parameters (?c - cube ?b - box) :precondition () :effect (in ?c ?b)))"
    )
    state = State(frozenset(), {"c1": "cube", "b1": "box", "b2": "box"})
    d = check_step(domain, state, Step("put", ("b2", "b1")))
    assert [r.kind for r in d.reasons] == [ReasonKind.TYPE_MISMATCH]
    assert d.reasons[0].detail == "argument 1 (?c) must be a cube, but b2 is a box"
    assert d.hints == ("objects of type cube: c1",)


def test_each_failing_conjunct_is_reported(blocks) -> None:
    domain, state = blocks
    after = check_step(domain, state, Step("pick-up", ("a",))).next_state
    d = check_step(domain, after, Step("unstack", ("b", "c")))
    literals = [r.literal for r in d.reasons]
    assert literals == ["(on b c)", "(handempty)"]
    assert all(r.kind is ReasonKind.UNSATISFIED_PRECONDITION for r in d.reasons)
    assert d.message == "(unstack b c): precondition (on b c) is false (+1 more)"


def test_forall_witness_and_deleting_hint(tabletop) -> None:
    domain, state = tabletop
    d = check_step(domain, state, Step("pick", ("red_box", "table")))
    assert not d.ok
    reason = d.reasons[0]
    assert reason.literal == "(not (on blue_cube1 red_box))"
    assert reason.bindings == (("?z", "blue_cube1"),)
    assert (
        d.message
        == "(pick red_box table): precondition (not (on blue_cube1 red_box)) is false: blue_cube1 is on red_box"
    )
    # a GSR-Bench cube on a box is stuck there: the only achiever cannot apply
    assert d.hints[0].startswith("(pick blue_cube1 red_box) deletes (on blue_cube1 red_box), but it needs")


def test_drawer_hint_closes_the_drawer_above(tabletop) -> None:
    domain, state = tabletop
    d = check_step(domain, state, Step("open", ("short_cabinet/drawer_low",)))
    assert [r.literal for r in d.reasons] == ["(not (open short_cabinet/drawer_high))"]
    assert d.reasons[0].bindings == (("?d", "short_cabinet/drawer_high"),)
    assert d.hints[0].startswith("(close short_cabinet/drawer_high) first")


def test_disjunction_reports_every_branch(tabletop) -> None:
    domain, state = tabletop
    d = check_step(domain, state, Step("pick", ("red_cube1", "blue_box")))
    reason = d.reasons[0]
    assert reason.literal == "(or (on red_cube1 blue_box) (in red_cube1 blue_box))"
    assert "no alternative holds" in reason.detail and "(on red_cube1 table) holds instead" in reason.detail
    assert any(h.startswith("(place_on red_cube1 blue_box)") for h in d.hints)


def test_static_precondition_says_it_can_never_hold(tabletop) -> None:
    domain, state = tabletop
    d = check_step(domain, state, Step("open", ("red_box",)))
    assert d.reasons[0].literal == "(openable red_box)"
    assert d.hints[0].startswith("(openable red_box) can never become true (no action changes openable)")
    assert "short_cabinet/drawer_low" in d.hints[0]


def test_exists_without_witness() -> None:
    domain = parse_domain(
        "(define (domain e) (:predicates (on ?x ?y) (clear ?x))"
        " (:action a :parameters (?x) :precondition (exists (?y) (on ?y ?x)) :effect (clear ?x)))"
    )
    state = State(frozenset({Atom("on", ("b", "c"))}), {"a": "object", "b": "object", "c": "object"})
    d = check_step(domain, state, Step("a", ("a",)))
    assert d.reasons[0].literal == "(exists (?y) (on ?y a))"
    assert d.reasons[0].detail == "precondition (exists (?y) (on ?y a)) is false: no object satisfies it"


def test_claimed_effects_are_compared(blocks) -> None:
    domain, state = blocks
    claim = Step(
        "pick-up",
        ("a",),
        add=(Atom("holding", ("a",)), Atom("on", ("a", "b"))),
        delete=(Atom("clear", ("a",)),),
    )
    d = check_step(domain, state, claim)
    assert not d.ok and {r.kind for r in d.reasons} == {ReasonKind.EFFECT_MISMATCH}
    assert [r.literal for r in d.reasons] == ["(on a b)", "(not (handempty))", "(not (ontable a))"]
    assert d.reasons[0].detail == "claimed add effect (on a b) is not an effect of the action"
    assert d.hints == (
        "the true effects are: (holding a) (not (clear a)) (not (handempty)) (not (ontable a))",
    )
    exact = Step(
        "pick-up",
        ("a",),
        add=(Atom("holding", ("a",)),),
        delete=(Atom("clear", ("a",)), Atom("handempty"), Atom("ontable", ("a",))),
    )
    assert check_step(domain, state, exact).ok


def test_goal_reasons_and_hints(blocks) -> None:
    domain, state = blocks
    reasons, hints = explain_goal(domain, parse_formula("(and (holding a) (clear b) (on c d))"), state)
    assert [r.kind for r in reasons] == [ReasonKind.GOAL_UNSATISFIED] * 2
    assert [r.literal for r in reasons] == ["(holding a)", "(on c d)"]
    assert hints[0] == "(pick-up a) first (it adds (holding a))"
    assert explain_goal(domain, parse_formula("(clear b)"), state) == ([], [])


def test_case_insensitive_step_and_determinism(blocks) -> None:
    domain, state = blocks
    assert check_step(domain, state, Step("PICK-UP", ("A",))).ok
    first = check_step(domain, state, Step("unstack", ("a", "b"))).to_dict()
    fresh = State(state.atoms, dict(state.objects))  # no caches
    assert check_step(domain, fresh, Step("unstack", ("a", "b"))).to_dict() == first
    assert "hint: " in str(check_step(domain, state, Step("unstack", ("a", "b"))))
