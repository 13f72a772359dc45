"""Building-scale scene graphs: floors, rooms, receptacles, objects, people with schedules, navigation.

Pure core logic over numpy and the ``SceneGraph`` types; the delivery benchmark (``gsr.benchmarks.delivery``)
builds on it. Names are re-exported lazily so ``import gsr.building`` stays cheap.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

_EXPORTS: dict[str, str] = {
    "Building": "gsr.building.model",
    "Floor": "gsr.building.model",
    "Room": "gsr.building.model",
    "Receptacle": "gsr.building.model",
    "Item": "gsr.building.model",
    "Person": "gsr.building.model",
    "Slot": "gsr.building.model",
    "Connector": "gsr.building.model",
    "load_building": "gsr.building.model",
    "save_building": "gsr.building.model",
    "generate_building": "gsr.building.generator",
    "building_problems": "gsr.building.checks",
    "building_graph": "gsr.building.graph",
    "BuildingMap": "gsr.building.navigation",
    "Route": "gsr.building.navigation",
    "astar": "gsr.building.navigation",
    "PeopleClock": "gsr.building.people",
    "daily_schedule": "gsr.building.people",
    "shipped_building_path": "gsr.building.shipped",
    "load_shipped_building": "gsr.building.shipped",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.building", _EXPORTS, globals())
