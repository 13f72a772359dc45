"""The delivery agent's building knowledge: map knowledge from the building graph, grown by observations."""

from __future__ import annotations

from gsr.benchmarks.delivery.building.graph import building_graph
from gsr.benchmarks.delivery.knowledge import BuildingKnowledge
from gsr.benchmarks.delivery.reference import ObjectRef
from gsr.benchmarks.delivery.world import Observation


def test_map_knowledge(shipped) -> None:
    knowledge = BuildingKnowledge(building_graph(shipped, items=False), shipped.cell_size)
    assert set(knowledge.receptacles) == {r.id for r in shipped.receptacles}
    for r in shipped.receptacles:
        info = knowledge.receptacles[r.id]
        assert info.room == r.room and info.closed == r.closed and info.relation == r.relation
        assert info.place == (shipped.room(r.room).floor, *r.access)
    assert knowledge.room_kind == {r.id: r.kind for r in shipped.rooms}
    assert knowledge.items_matching(ObjectRef(category="mug")) == []


def test_observations_update_the_graph(shipped) -> None:
    knowledge = BuildingKnowledge(building_graph(shipped, items=False), shipped.cell_size)
    fridge = next(r for r in shipped.receptacles if r.category == "fridge")
    desk = next(r for r in shipped.receptacles if r.category == "desk")
    obs = Observation(
        room=fridge.room,
        time=1000.0,
        items={"mug_99": ("mug", "red", fridge.id), "mug_98": ("mug", "blue", desk.id)},
        people={"imani": (0, 5, 6)},
    )
    knowledge.observe(obs)
    g = knowledge.graph
    assert ("mug_99", "in", fridge.id) in {e.key() for e in g.edges}
    assert ("mug_98", "on", desk.id) in {e.key() for e in g.edges}
    assert ("imani", "in", fridge.room) in {e.key() for e in g.edges}
    assert knowledge.items_matching(ObjectRef(category="mug", color="red")) == [("mug_99", fridge.id)]
    assert knowledge.items_matching(ObjectRef(category="mug", receptacle="desk")) == [("mug_98", desk.id)]
    assert knowledge.items_matching(ObjectRef(category="mug", room=desk.room)) == [("mug_98", desk.id)]
    assert knowledge.sighting("imani") == (1000.0, (0, 5, 6))
    # seen again elsewhere: the support edge moves, no duplicate
    knowledge.observe(Observation(room=desk.room, time=1010.0, items={"mug_99": ("mug", "red", desk.id)}))
    assert [e.target for e in knowledge.graph.edges if e.source == "mug_99"] == [desk.id]
    knowledge.forget("imani")
    assert knowledge.sighting("imani") is None and not knowledge.graph.has_node("imani")
