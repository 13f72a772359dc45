"""The agent's belief graph: map knowledge from the building graph, grown by observations."""

from __future__ import annotations

from gsr.benchmarks.delivery.belief import Belief
from gsr.benchmarks.delivery.reference import ObjectRef
from gsr.benchmarks.delivery.world import Observation

from gsr.building.graph import building_graph


def test_map_knowledge(shipped) -> None:
    belief = Belief(building_graph(shipped, items=False), shipped.cell_size)
    assert set(belief.receptacles) == {r.id for r in shipped.receptacles}
    for r in shipped.receptacles:
        info = belief.receptacles[r.id]
        assert info.room == r.room and info.closed == r.closed and info.relation == r.relation
        assert info.place == (shipped.room(r.room).floor, *r.access)
    assert belief.room_kind == {r.id: r.kind for r in shipped.rooms}
    assert belief.items_matching(ObjectRef(category="mug")) == []


def test_observations_update_the_graph(shipped) -> None:
    belief = Belief(building_graph(shipped, items=False), shipped.cell_size)
    fridge = next(r for r in shipped.receptacles if r.category == "fridge")
    desk = next(r for r in shipped.receptacles if r.category == "desk")
    obs = Observation(
        room=fridge.room,
        time=1000.0,
        items={"mug_99": ("mug", "red", fridge.id), "mug_98": ("mug", "blue", desk.id)},
        people={"imani": (0, 5, 6)},
    )
    belief.observe(obs)
    g = belief.graph
    assert ("mug_99", "in", fridge.id) in {e.key() for e in g.edges}
    assert ("mug_98", "on", desk.id) in {e.key() for e in g.edges}
    assert ("imani", "in", fridge.room) in {e.key() for e in g.edges}
    assert belief.items_matching(ObjectRef(category="mug", color="red")) == [("mug_99", fridge.id)]
    assert belief.items_matching(ObjectRef(category="mug", receptacle="desk")) == [("mug_98", desk.id)]
    assert belief.items_matching(ObjectRef(category="mug", room=desk.room)) == [("mug_98", desk.id)]
    assert belief.sighting("imani") == (1000.0, (0, 5, 6))
    # seen again elsewhere: the support edge moves, no duplicate
    belief.observe(Observation(room=desk.room, time=1010.0, items={"mug_99": ("mug", "red", desk.id)}))
    assert [e.target for e in belief.graph.edges if e.source == "mug_99"] == [desk.id]
    belief.forget("imani")
    assert belief.sighting("imani") is None and not belief.graph.has_node("imani")
