"""PyBullet world and meta-skill library (see ARCHITECTURE.md and docs/skills.md).

Heavy dependencies (pybullet, gymnasium) load lazily: ``import skills`` stays cheap, and attribute
access (``skills.build_world``) imports the module that defines it.
"""

from __future__ import annotations

import importlib
from typing import Any

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


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'skills' has no attribute {name!r}")
