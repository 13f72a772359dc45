"""The lark instruction parser with the building's lexicon."""

from __future__ import annotations

import pytest
from gsr.benchmarks.delivery.building.graph import building_graph
from gsr.benchmarks.delivery.parser import lexicon_from_graph
from gsr.benchmarks.delivery.reference import ObjectRef, PersonRef
from gsr.benchmarks.delivery.tasks import generate_tasks

from gsr.errors import GSRError


def test_lexicon_comes_from_the_graph(shipped) -> None:
    lex = lexicon_from_graph(
        building_graph(shipped, people_rooms={p.id: p.home_room for p in shipped.people})
    )
    assert lex.objects["water bottle"] == "water_bottle"
    assert lex.receptacles["dining table"] == "dining_table"
    assert lex.rooms["kitchen"].startswith("kitchen_")
    assert set(lex.names.values()) == {p.id for p in shipped.people}
    assert len(lex.objects) == len({it.category for it in shipped.items})


def test_parses_the_issue_style_sentence(shipped, parser) -> None:
    kitchen = next(r for r in shipped.rooms if r.kind == "kitchen")
    office = next(r for r in shipped.rooms if r.kind == "office")
    imani = shipped.person("imani")
    ref = parser.parse(
        "Fetch the blue water bottle from the dining table in the kitchen and deliver it to "
        f"Imani, the woman in the {imani.appearance.color} {imani.appearance.garment}, in {office.name}."
    )
    assert ref.object == ObjectRef(
        category="water_bottle", color="blue", receptacle="dining_table", room=kitchen.id
    )
    assert ref.person == PersonRef(
        name="imani",
        gender="woman",
        color=imani.appearance.color,
        garment=imani.appearance.garment,
        room=office.id,
    )


def test_description_without_name(parser) -> None:
    ref = parser.parse("Can you bring the man with glasses the red mug?")
    assert ref.person == PersonRef(gender="man", glasses=True)
    assert ref.object == ObjectRef(category="mug", color="red")


@pytest.mark.parametrize(
    "text",
    ["Fetch the golden chalice and deliver it to Imani.", "Bring the mug to Zorro.", "Dance with Imani.", ""],
)
def test_unknown_words_are_errors(parser, text: str) -> None:
    with pytest.raises(GSRError, match="cannot parse instruction"):
        parser.parse(text)


def test_parses_every_val_instruction(shipped, parser) -> None:
    for t in generate_tasks(shipped, "val"):
        assert parser.parse(t.instruction) == t.reference, t.instruction
