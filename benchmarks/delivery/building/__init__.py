"""The delivery benchmark's world model: building-scale scene graphs (floors, rooms, receptacles,
objects, people with schedules), navigation, and the PRS station read from PRS's map files.

Plain logic over numpy and the core ``SceneGraph`` types. It lives in the delivery package because only
the delivery benchmark (its tasks, simulated episodes, agents and the PRS environment) uses it; the core
knows nothing of buildings. Names are re-exported lazily so importing the package stays cheap.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

_EXPORTS: dict[str, str] = {
    "Building": "gsr.benchmarks.delivery.building.model",
    "Floor": "gsr.benchmarks.delivery.building.model",
    "Room": "gsr.benchmarks.delivery.building.model",
    "Receptacle": "gsr.benchmarks.delivery.building.model",
    "Item": "gsr.benchmarks.delivery.building.model",
    "Person": "gsr.benchmarks.delivery.building.model",
    "Slot": "gsr.benchmarks.delivery.building.model",
    "Connector": "gsr.benchmarks.delivery.building.model",
    "load_building": "gsr.benchmarks.delivery.building.model",
    "save_building": "gsr.benchmarks.delivery.building.model",
    "generate_building": "gsr.benchmarks.delivery.building.generator",
    "building_problems": "gsr.benchmarks.delivery.building.checks",
    "building_graph": "gsr.benchmarks.delivery.building.graph",
    "BuildingMap": "gsr.benchmarks.delivery.building.navigation",
    "Route": "gsr.benchmarks.delivery.building.navigation",
    "astar": "gsr.benchmarks.delivery.building.navigation",
    "PeopleClock": "gsr.benchmarks.delivery.building.people",
    "daily_schedule": "gsr.benchmarks.delivery.building.people",
    "shipped_building_path": "gsr.benchmarks.delivery.building.shipped",
    "load_shipped_building": "gsr.benchmarks.delivery.building.shipped",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.benchmarks.delivery.building", _EXPORTS, globals())
