"""Property test: any reference over the building's lexicon, rendered by any template, parses back."""

from __future__ import annotations

import numpy as np
from gsr.benchmarks.delivery.building.catalog import RECEPTACLES
from gsr.benchmarks.delivery.building.shipped import load_shipped_building
from gsr.benchmarks.delivery.reference import ObjectRef, PersonRef
from gsr.benchmarks.delivery.run import parser_for
from gsr.benchmarks.delivery.tasks import TEMPLATES, object_phrase, person_phrase, room_text
from hypothesis import given, settings
from hypothesis import strategies as st

BUILDING = load_shipped_building()
PARSER = parser_for(BUILDING)
NAMES = {it.category: it.name for it in BUILDING.items}
ROOMS = [r.id for r in BUILDING.rooms]
COLORS = sorted({it.color for it in BUILDING.items} | {p.appearance.color for p in BUILDING.people})

objects = st.builds(
    ObjectRef,
    category=st.sampled_from(sorted(NAMES)),
    color=st.none() | st.sampled_from(COLORS),
    receptacle=st.none() | st.sampled_from(sorted({r.category for r in BUILDING.receptacles})),
    room=st.none() | st.sampled_from(ROOMS),
)


@st.composite
def persons(draw: st.DrawFn) -> PersonRef:
    p = draw(st.sampled_from(BUILDING.people))
    a = p.appearance
    named = draw(st.booleans())
    head = draw(st.sampled_from(["gender", "role"]))  # a description is headed by one of them
    described = draw(st.booleans()) or not named
    fields: dict[str, object] = {"name": p.id if named else None}
    if described:
        fields[head] = a.gender if head == "gender" else p.role
        if draw(st.booleans()):
            fields["garment"], fields["color"] = a.garment, a.color
        if draw(st.booleans()):
            fields["hair"] = a.hair
        if draw(st.booleans()):
            fields["glasses"] = True
    fields["room"] = draw(st.none() | st.sampled_from(ROOMS))
    return PersonRef(**fields)


@settings(max_examples=150, deadline=None)
@given(obj=objects, person=persons(), template=st.sampled_from(TEMPLATES), seed=st.integers(0, 2**16))
def test_rendered_references_parse_back(obj: ObjectRef, person: PersonRef, template: str, seed: int) -> None:
    if "{where}" in template and obj.receptacle is None:
        template = TEMPLATES[0]
    rng = np.random.default_rng(seed)
    bare = "the " + (f"{obj.color} " if obj.color else "") + NAMES[obj.category]
    where = ""
    if obj.receptacle:
        where = f"{RECEPTACLES[obj.receptacle].relation} the {obj.receptacle.replace('_', ' ')}"
        if obj.room:
            where += f" in {room_text(BUILDING, obj.room)}"
    text = template.format(
        obj=object_phrase(BUILDING, obj, NAMES, rng),
        person=person_phrase(BUILDING, person),
        bare=bare,
        where=where,
    )
    parsed = PARSER.parse(text)
    assert parsed.object == obj, text
    assert parsed.person == person, text
