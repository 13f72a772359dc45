"""BDDL reader (LIBERO and BEHAVIOR) and the forn / forpairs expansion."""

from __future__ import annotations

import itertools
import math

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gsr.errors import GSRError, ParseError
from gsr.pddl import (
    And,
    Atom,
    Exists,
    Forall,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Not,
    Or,
    TypedVar,
    expand_quantifiers,
    load_bddl,
    parse_bddl,
    parse_bddl_domain,
    parse_formula,
)
from tests.data_paths import BEHAVIOR as BEHAVIOR_DIR
from tests.data_paths import LIBERO as LIBERO_DIR

LIBERO = sorted(LIBERO_DIR.glob("*/*.bddl"))
BEHAVIOR = sorted(p for p in BEHAVIOR_DIR.glob("*.bddl") if p.name != "domain_igibson.bddl")


def test_every_shipped_file_loads() -> None:
    assert len(LIBERO) == 40 and len(BEHAVIOR) == 5
    for path in LIBERO:
        problem = load_bddl(path)
        assert problem.domain_name == "robosuite" and problem.language and problem.regions and problem.init
        # region targets need not be declared (some files name absent fixtures); ranges are x0 y0 x1 y1
        assert all(len(box) == 4 for r in problem.regions for box in r.ranges)
    for path in BEHAVIOR:
        problem = load_bddl(path)
        assert problem.domain_name == "igibson" and problem.objects and problem.language is None
    domain = parse_bddl_domain((BEHAVIOR_DIR / "domain_igibson.bddl").read_text())
    assert domain.name == "igibson" and len(domain.predicates) == 17 and not domain.actions
    assert domain.predicates["ontop"].arity == 2


def test_libero_kitchen_scene4() -> None:
    name = "KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it.bddl"
    problem = load_bddl(LIBERO_DIR / "libero_10" / name)
    assert problem.name == "libero_kitchen_tabletop_manipulation"
    assert problem.language == "put the black bowl in the bottom drawer of the cabinet and close it"
    assert len(problem.regions) == 9
    first = problem.regions[0]
    assert (first.name, first.target, first.qualified_name) == (
        "white_cabinet_init_region",
        "kitchen_table",
        "kitchen_table_white_cabinet_init_region",
    )
    assert first.ranges == ((-0.01, 0.29, 0.01, 0.31),) and first.yaw_rotation == ((0.0, 0.0),)
    assert problem.regions[1].yaw_rotation == ((math.pi, math.pi),)
    drawer = problem.regions[7]
    assert (drawer.qualified_name, drawer.ranges) == ("white_cabinet_1_bottom_region", ())
    assert problem.fixtures == {
        "kitchen_table": "kitchen_table",
        "white_cabinet_1": "white_cabinet",
        "wine_rack_1": "wine_rack",
    }
    assert problem.objects == {"akita_black_bowl_1": "akita_black_bowl", "wine_bottle_1": "wine_bottle"}
    assert problem.obj_of_interest == ["akita_black_bowl_1", "white_cabinet_1"]
    assert len(problem.init) == 5
    assert problem.init[0] == Atom("on", ("akita_black_bowl_1", "kitchen_table_akita_black_bowl_init_region"))
    assert problem.init[-1] == Atom("open", ("white_cabinet_1_bottom_region",))
    assert problem.goal == And(
        (
            Atom("close", ("white_cabinet_1_bottom_region",)),  # kept as a plain atom
            Atom("in", ("akita_black_bowl_1", "white_cabinet_1_bottom_region")),
        )
    )


def test_behavior_goals() -> None:
    tea = load_bddl(BEHAVIOR_DIR / "making_tea.bddl")
    assert tea.goal.parts[1] == Atom("ontop", ("teapot.n.01_1", "stove.n.01_1"))  # '?object' stored bare
    assert Atom("inroom", ("cabinet.n.01_1", "kitchen")) in tea.init  # a room, not an object
    candles = load_bddl(BEHAVIOR_DIR / "setting_up_candles.bddl")
    candle = TypedVar("?candle.n.01", ("candle.n.01",))
    assert candles.goal.parts[0] == ForN(3, (candle,), Atom("ontop", ("?candle.n.01", "table.n.02_1")))
    dishes = load_bddl(BEHAVIOR_DIR / "putting_dishes_away_after_cleaning.bddl")
    exists = dishes.goal.parts[0]
    assert isinstance(exists, Exists) and isinstance(exists.body, Forall)
    assert exists.body.body == Atom("inside", ("?plate.n.04", "cabinet.n.01_1"))  # bound kept, object bare


LIBERO_SAMPLE = """
(define (problem Sample)
  (:domain robosuite)
  (:language Open the TOP drawer, then put the bowl on the plate)
  (:regions
    (plate_region (:target main_table) (:ranges ((0.1 0.2 0.3 0.4) (-1 -1 1 1)))
                  (:yaw_rotation ((-pi/2 pi))) (:rgba (0 0 1 0.5)) (:shape box))
    (top_region (:target cabinet_1)))
  (:fixtures main_table - table cabinet_1 - cabinet)
  (:objects bowl_1 plate_1 - bowl)
  (:obj_of_interest bowl_1)
  (:init (On bowl_1 main_table_plate_region) (Open cabinet_1_top_region))
  (:goal (And (Or (On bowl_1 plate_1) (In bowl_1 cabinet_1_top_region)) (Not (Open cabinet_1_top_region))
              (TurnOn cabinet_1))))
"""


def test_libero_dialect_features() -> None:
    problem = parse_bddl(LIBERO_SAMPLE)
    assert problem.language == "Open the TOP drawer, then put the bowl on the plate"  # original case kept
    region = problem.regions[0]
    assert region.ranges == ((0.1, 0.2, 0.3, 0.4), (-1.0, -1.0, 1.0, 1.0))
    assert region.yaw_rotation == ((-math.pi / 2, math.pi),)
    assert region.extra == {"rgba": (0.0, 0.0, 1.0, 0.5), "shape": "box"}
    assert problem.goal.parts[1] == Not(Atom("open", ("cabinet_1_top_region",)))
    assert isinstance(problem.goal.parts[0], Or) and problem.goal.parts[2] == Atom("turnon", ("cabinet_1",))


BEHAVIOR_SAMPLE = """
(define (problem packing_lunch_0)
  (:domain igibson)
  (:objects bag.n.01_1 bag.n.01_2 - bag.n.01  apple.n.01_1 apple.n.01_2 apple.n.01_3 - apple.n.01
            counter.n.01_1 - counter.n.01)
  (:init (ontop apple.n.01_1 counter.n.01_1) (not (open bag.n.01_1)) (inroom counter.n.01_1 kitchen))
  (:goal (and
    (forpairs (?bag.n.01 - bag.n.01) (?apple.n.01 - apple.n.01) (inside ?apple.n.01 ?bag.n.01))
    (fornpairs (1) (?bag.n.01 - bag.n.01) (?apple.n.01 - apple.n.01) (ontop ?apple.n.01 ?bag.n.01))
    (forall (?apple.n.01 - apple.n.01) (imply (sliced ?apple.n.01) (not (ontop ?apple.n.01 ?counter.n.01_1))))
    (exists (?bag.n.01 - bag.n.01) (forn (2) (?apple.n.01 - apple.n.01) (inside ?apple.n.01 ?bag.n.01))))))
"""


def test_behavior_quantifiers() -> None:
    problem = parse_bddl(BEHAVIOR_SAMPLE)
    assert problem.init_false == [Atom("open", ("bag.n.01_1",))]
    pairs, npairs, forall, exists = problem.goal.parts
    assert isinstance(pairs, ForPairs) and pairs.first == (TypedVar("?bag.n.01", ("bag.n.01",)),)
    # fornpairs (1): one pair among 2 bags x 3 apples, expanded on reading
    assert isinstance(npairs, Or) and len(npairs.parts) == 6
    assert And((Atom("ontop", ("apple.n.01_3", "bag.n.01_2")),)) in npairs.parts
    assert isinstance(forall.body, Imply)
    assert forall.body.then == Not(Atom("ontop", ("?apple.n.01", "counter.n.01_1")))
    assert isinstance(exists.body, ForN) and exists.body.count == 2


# ------------------------------------------------------------- expansion


def _holds(formula: Formula, true: set[Atom]) -> bool:
    match formula:
        case Atom():
            return formula in true
        case Not(formula=f):
            return not _holds(f, true)
        case And(parts=parts):
            return all(_holds(p, true) for p in parts)
        case Or(parts=parts):
            return any(_holds(p, true) for p in parts)
    raise AssertionError(formula)


def _objects(n_cups: int, n_boxes: int) -> dict[str, str]:
    return {**{f"cup{i}": "cup" for i in range(n_cups)}, **{f"box{i}": "box" for i in range(n_boxes)}}


@settings(max_examples=120, deadline=None)
@given(
    n_cups=st.integers(0, 4),
    n_boxes=st.integers(0, 4),
    count=st.integers(0, 5),
    facts=st.sets(st.tuples(st.integers(0, 3), st.integers(0, 3))),
)
def test_expansion_matches_brute_force(
    n_cups: int, n_boxes: int, count: int, facts: set[tuple[int, int]]
) -> None:
    objects = _objects(n_cups, n_boxes)
    cups = [o for o, t in objects.items() if t == "cup"]
    boxes = [o for o, t in objects.items() if t == "box"]
    true = {Atom("in", (f"cup{c}", f"box{b}")) for c, b in facts if c < n_cups and b < n_boxes}
    x, y = TypedVar("?x", ("cup",)), TypedVar("?y", ("box",))
    body = Atom("in", ("?x", "?y"))

    forn = ForN(count, (x,), Atom("in", ("?x", "box0")))
    satisfied = sum(Atom("in", (c, "box0")) in true for c in cups)
    assert _holds(expand_quantifiers(forn, objects), true) == (satisfied >= count)

    # forpairs: a matching that covers every cup (networkx is an independent oracle)
    graph = nx.Graph()
    graph.add_nodes_from(cups + boxes)
    graph.add_edges_from((a.args[0], a.args[1]) for a in true)
    matching = nx.bipartite.maximum_matching(graph, top_nodes=cups) if cups else {}
    covered = sum(1 for c in cups if c in matching)
    assert _holds(expand_quantifiers(ForPairs((x,), (y,), body), objects), true) == (covered == len(cups))

    # nesting: forn inside a forpairs body is expanded too, and substitution reaches it
    nested = expand_quantifiers(Not(ForN(1, (y,), body)), objects)
    assert _holds(nested, true) == (not any(Atom("in", ("?x", b)) in true for b in boxes))


def test_expansion_shape_subtypes_and_guard() -> None:
    objects = {"a": "cube", "b": "cube", "c": "mug", "t": "table"}
    f = ForN(2, (TypedVar("?o", ("item",)),), Atom("on", ("?o", "t")))
    assert expand_quantifiers(f, objects) == Or(())  # no object is exactly an "item"
    expanded = expand_quantifiers(f, objects, lambda sub, sup: sup in (sub, "item") and sub != "table")
    assert expanded == Or(
        tuple(And((Atom("on", (p, "t")), Atom("on", (q, "t")))) for p, q in itertools.combinations("abc", 2))
    )
    # other nodes and variables bound further out stay as they are
    outer = Forall((TypedVar("?t"),), ForN(1, (TypedVar("?o", ("mug",)),), Atom("on", ("?o", "?t"))))
    assert expand_quantifiers(outer, objects) == Forall(
        (TypedVar("?t"),), Or((And((Atom("on", ("c", "?t")),)),))
    )
    many = {f"o{i}": "thing" for i in range(40)}
    with pytest.raises(GSRError, match="100,000"):
        expand_quantifiers(ForN(20, (TypedVar("?o", ("thing",)),), Atom("p", ("?o",))), many)
    ten = {**{f"a{i}": "a" for i in range(10)}, **{f"b{i}": "b" for i in range(10)}}
    pairs = ForPairs((TypedVar("?x", ("a",)),), (TypedVar("?y", ("b",)),), Atom("p", ("?x", "?y")))
    with pytest.raises(GSRError, match="100,000"):
        expand_quantifiers(pairs, ten)
    assert parse_formula("(forpairs (?x - a) (?y - b) (p ?x ?y))") == pairs


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("text", "message", "marker"),
    [
        ("(define (problem p) (:domain d)\n  (:objects a - t)\n  (:goal (and (on a b))", "end of file", None),
        (
            "(define (problem p) (:domain d)\n  (:scenery (x))\n  (:goal (and)))",
            "unknown section or keyword ':scenery'",
            ":scenery",
        ),
        (
            "(define (problem p) (:domain d)\n  (:objects a - t)\n  (:goal (on a ghost)))",
            "unknown object 'ghost'",
            "ghost",
        ),
        ("(define (problem p) (:domain d)\n  (:objects a - t)\n  (:goal (on ?a ?b)))", "?b is neither", "?b"),
        (
            "(define (problem p) (:domain d)\n  (:regions (r (:ranges ((0 0 1 1)))))\n  (:goal (and)))",
            "needs (:target",
            "(r ",
        ),
        (
            "(define (problem p) (:domain d)\n  (:objects a - t)\n  (:objects b - t) (:goal (and)))",
            "duplicate (:objects)",
            "(:objects b",
        ),
        ("(define (problem p) (:domain d) (:init (p)))", "no (:goal", "(define"),
    ],
)
def test_malformed_bddl(text: str, message: str, marker: str | None) -> None:
    with pytest.raises(ParseError) as info:
        parse_bddl(text, "task.bddl")
    err = info.value
    assert message in err.message and err.source == "task.bddl"
    if marker is None:
        assert err.line == text.count("\n") + 1
    else:
        offset = text.rindex(marker)
        assert (err.line, err.column) == (
            text.count("\n", 0, offset) + 1,
            offset - text.rfind("\n", 0, offset),
        )


def test_empty_bddl_file() -> None:
    with pytest.raises(ParseError, match=r"^x\.bddl:1:1: empty file$"):
        parse_bddl("\n  \n", "x.bddl")
