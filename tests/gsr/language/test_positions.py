"""Positional modifiers, sides beside an object, levels of shelves and 'under': hand-built scenes.

Object positions come from the graph: the ``region`` attribute a node starts in (LIBERO's
``akita_black_bowl_back_init``) or left_of/front_of edges. Where they do not single out one object,
the grounder must fail naming the candidates, never pick one.
"""

from __future__ import annotations

import pytest

from gsr.language import ground
from gsr.language.errors import GroundingError
from gsr.pddl.writer import write_formula
from gsr.scene_graph import Edge, Node, SceneGraph


def _goal(text: str, g: SceneGraph) -> str:
    return " ".join(write_formula(ground(text, g).formula).split())


def _on_table(*ids: str) -> list[Edge]:
    return [Edge(source=i, relation="on", target="table") for i in ids]


def _bowls(with_regions: bool = True) -> SceneGraph:
    """Three black bowls front to back, a plate, a tray, two butters and a cabinet with drawers."""
    where = {"bowl_1": "front", "bowl_2": "middle", "bowl_3": "back"}
    nodes = [
        Node(id="table", category="table"),
        *(
            Node(
                id=b,
                category="bowl",
                attributes={"color": "black", **({"region": f"black_bowl_{w}_init"} if with_regions else {})},
            )
            for b, w in where.items()
        ),
        Node(id="plate_1", category="plate", attributes={"region": "plate_init"}),
        Node(id="butter_1", category="butter", attributes={"region": "butter_front_init"}),
        Node(id="butter_2", category="butter", attributes={"region": "butter_back_init"}),
        Node(id="cabinet_1", category="cabinet"),
        Node(id="cabinet_1/top_side", category="cabinet_top", parent="cabinet_1"),
        *(
            Node(id=f"cabinet_1/{w}_drawer", category="drawer", attributes={"level": lv}, parent="cabinet_1")
            for w, lv in (("top", 2), ("middle", 1), ("bottom", 0))
        ),
    ]
    edges = _on_table(*where, "plate_1", "butter_1", "butter_2", "cabinet_1")
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("put the black bowl at the back on the plate", "(and (on bowl_3 plate_1))"),
        ("put the black bowl at the front on the plate", "(and (on bowl_1 plate_1))"),
        ("put the black bowl in the middle on the plate", "(and (on bowl_2 plate_1))"),
        ("put the middle black bowl on the plate", "(and (on bowl_2 plate_1))"),
        ("put the bowl that is at the back on the plate", "(and (on bowl_3 plate_1))"),
        ("stack the black bowl at the front on the black bowl in the middle", "(and (on bowl_1 bowl_2))"),
        ("pick up the bowl at the back and put it on the plate", "(and (on bowl_3 plate_1))"),
    ],
)
def test_position_after_the_noun(text: str, expected: str) -> None:
    """'the bowl at the back' means the same as 'the back bowl'."""
    assert _goal(text, _bowls()) == expected


def test_location_phrase_before_the_destination() -> None:
    """'put the butter at the back in the top drawer': the phrase picks the butter, the drawer is the goal."""
    g = _bowls()
    assert _goal("put the butter at the back in the top drawer of the cabinet and close it", g) == (
        "(and (in butter_2 cabinet_1/top_drawer) (not (open cabinet_1/top_drawer)))"
    )
    assert _goal("put the butter at the front in the top drawer of the cabinet", g) == (
        "(and (in butter_1 cabinet_1/top_drawer))"
    )


def test_on_top_of_it_refers_to_the_earlier_object() -> None:
    """'it' is the drawer just closed (never the bowl being put); the top of a drawer is its cabinet's top."""
    assert _goal(
        "close the top drawer of the cabinet and put the black bowl at the back on top of it", _bowls()
    ) == ("(and (not (open cabinet_1/top_drawer)) (on bowl_3 cabinet_1/top_side))")


def test_positions_unknown_is_an_error_with_candidates() -> None:
    """Without region attributes or side edges, 'the bowl at the back' names none of the three: error."""
    g = _bowls(with_regions=False)
    with pytest.raises(GroundingError) as exc:
        ground("put the black bowl at the back on the plate", g)
    assert set(exc.value.candidates) == {"bowl_1", "bowl_2", "bowl_3"}
    with pytest.raises(GroundingError) as exc:
        ground("put the black bowl on the plate", _bowls())
    assert "ambiguous" in exc.value.message
    assert set(exc.value.candidates) == {"bowl_1", "bowl_2", "bowl_3"}


def _books(right: bool = True) -> SceneGraph:
    """Books on the left, (on the right) and one with no position; a shelf with a top side and two layers."""
    nodes = [
        Node(id="table", category="table"),
        Node(id="book_l", category="book", attributes={"color": "yellow", "region": "yellow_book_left_init"}),
        Node(id="book_m", category="book", attributes={"color": "black", "region": "black_book_init"}),
        Node(id="shelf_1", category="shelf"),
        Node(id="shelf_1/top_side", category="region", parent="shelf_1"),
        Node(id="shelf_1/top_region", category="compartment", parent="shelf_1"),
        Node(id="shelf_1/bottom_region", category="compartment", parent="shelf_1"),
    ]
    if right:
        nodes.append(
            Node(
                id="book_r",
                category="book",
                attributes={"color": "yellow", "region": "yellow_book_right_init"},
            )
        )
    ids = [n.id for n in nodes if n.parent is None and n.id != "table"]
    return SceneGraph(nodes=tuple(nodes), edges=tuple(_on_table(*ids)))


def test_book_on_the_left_right_and_in_the_middle() -> None:
    """Left/right from the region names; the middle one is the book at neither named end."""
    g = _books()
    assert _goal("put the book on the left on top of the shelf", g) == "(and (on book_l shelf_1/top_side))"
    assert _goal("pick up the book on the right and place it on top of the shelf", g) == (
        "(and (on book_r shelf_1/top_side))"
    )
    assert _goal("put the book in the middle under the shelf", g) == "(and (in book_m shelf_1/bottom_region))"


def test_middle_needs_both_ends() -> None:
    """With only a left book named, 'the book in the middle' is not determined: error with candidates."""
    with pytest.raises(GroundingError) as exc:
        ground("put the book in the middle on top of the shelf", _books(right=False))
    assert set(exc.value.candidates) >= {"book_l", "book_m"}


def test_layered_shelf_needs_a_level() -> None:
    """'on the shelf' with a top side and two layers does not say which: error naming the levels."""
    with pytest.raises(GroundingError) as exc:
        ground("put the book on the left on the cabinet shelf", _books())
    assert set(exc.value.candidates) == {"shelf_1/top_side", "shelf_1/top_region", "shelf_1/bottom_region"}


def test_under_without_a_bottom_part_is_an_error() -> None:
    """The domain has no 'under': without a bottom part of the object there is no goal to state."""
    with pytest.raises(GroundingError, match="under"):
        ground("put the book on the left under the table", _books())


def test_cabinet_word_for_a_shelf_is_an_error_naming_the_furniture() -> None:
    """'the cabinet' where the only furniture is a shelf: no silent substitution; the shelf is named."""
    with pytest.raises(GroundingError) as exc:
        ground("put the book on the left on top of the cabinet", _books())
    assert "shelf_1" in exc.value.candidates


def _caddy(beside: bool = True) -> SceneGraph:
    """A caddy with a right compartment; optionally a table region to the right of the caddy."""
    nodes = [
        Node(id="table", category="table"),
        Node(id="caddy_1", category="caddy"),
        Node(id="caddy_1/right_compartment", category="compartment", parent="caddy_1"),
        Node(id="mug_1", category="mug", attributes={"color": "red"}),
    ]
    if beside:
        nodes.append(Node(id="table/caddy_right_region", category="region", parent="table"))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(_on_table("caddy_1", "mug_1")))


def test_to_the_right_of_is_beside_not_inside() -> None:
    """'to the right of the caddy' is the table region beside it; 'the right compartment' is inside it."""
    g = _caddy()
    assert "(on mug_1 table/caddy_right_region)" in _goal(
        "pick up the red mug and place it to the right of the caddy", g
    )
    assert "(in mug_1 caddy_1/right_compartment)" in _goal(
        "pick up the red mug and place it in the right compartment of the caddy", g
    )


def test_to_the_right_of_without_a_region_is_an_error() -> None:
    """No region beside the caddy: an error, never the caddy's own right compartment."""
    with pytest.raises(GroundingError, match="region"):
        ground("put the red mug to the right of the caddy", _caddy(beside=False))
