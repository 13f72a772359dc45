"""PyBullet world and meta-skill library (see docs/architecture.md and docs/skills.md).

Heavy dependencies (pybullet, gymnasium) load lazily: ``import skills`` stays cheap, and attribute
access (``skills.build_world``) imports the module that defines it.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

_EXPORTS = {
    "build_world": "skills.build",
    "World": "skills.world",
    "layout_from_graph": "skills.layout",
    "scene_graph_from_sim": "skills.sim_graph",
    "graph_from_layout": "skills.sim_graph",
    "CameraSpec": "skills.camera",
    "default_views": "skills.camera",
    "render": "skills.camera",
    "render_frame": "skills.camera",
    "make_asset": "skills.assets",
    "asset_urdf_path": "skills.assets",
    "SkillResult": "skills.result",
    "Failure": "skills.result",
    "run_step": "skills.library",
    "execute_plan": "skills.executor",
    "ExecutionResult": "skills.executor",
    "PhysicalExecutor": "skills.executor",
    "symbolic_view": "skills.executor",
    "make_env": "skills.gym_env",
    "SimExecutor": "skills.sim_executor",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("skills", _EXPORTS, globals())
