"""PyBullet world and meta-skill library (see docs/architecture.md and docs/skills.md).

Heavy dependencies (pybullet, gymnasium) load lazily: ``import skills`` stays cheap, and attribute
access (``gsr.skills.build_world``) imports the module that defines it.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

_EXPORTS = {
    "build_world": "gsr.skills.build",
    "World": "gsr.skills.world",
    "layout_from_graph": "gsr.skills.layout",
    "scene_graph_from_sim": "gsr.skills.sim_graph",
    "graph_from_layout": "gsr.skills.sim_graph",
    "CameraSpec": "gsr.skills.camera",
    "default_views": "gsr.skills.camera",
    "render": "gsr.skills.camera",
    "render_frame": "gsr.skills.camera",
    "make_asset": "gsr.skills.assets",
    "asset_urdf_path": "gsr.skills.assets",
    "SkillResult": "gsr.skills.result",
    "Failure": "gsr.skills.result",
    "run_step": "gsr.skills.library",
    "execute_plan": "gsr.skills.executor",
    "ExecutionResult": "gsr.skills.executor",
    "PhysicalExecutor": "gsr.skills.executor",
    "symbolic_view": "gsr.skills.executor",
    "make_env": "gsr.skills.gym_env",
    "SimExecutor": "gsr.skills.sim_executor",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.skills", _EXPORTS, globals())
