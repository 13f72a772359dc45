"""The offline perception benchmark: simulated scenes, their rendering, and the scores of perception on them.

Modules (each also runs as ``python -m gsr.benchmarks.perception.<module>`` where it has a ``main``):

- ``scenes``: random tabletop scenes of primitive boxes with exact per-link labels and exact
  ground-truth graphs (``random_scene``, ``Scene``, ``SceneBuilder``); their bodies are written by the
  skills layer's URDF writer (``gsr.skills.urdf``), the one body writer of both layers;
- ``render``: look-at cameras on those scenes and their TinyRenderer frames (``camera_specs``,
  ``table_camera``, ``save_frame``; the function ``render.render``, which the package
  does not re-export: its name is the module's);
- ``eval``: ``gsr perceive-eval``: perception scored against the truth, on these scenes ("procedural")
  or on worlds of the skills layer ("skills"), with oracle masks or the trained detector
  (``evaluate``, ``format_report``, ``skills_scene``, ``procedural_scene``, ...);
- ``views``: which camera set sees the most (``study``, ``markdown``);
- ``train_data``: ``gsr perceive-train``: rendered frames with randomised light for the detector
  (``run_training``, ``training_frames``, ``heldout_frames``);
- ``node_errors``: missed and false nodes sorted by kind (``classify_errors``, ``run``);
- ``cpu_profile``: a CPU profile of ``perceive`` on rendered scenes.

The names below are the package's public API. They resolve on first use, so importing the package
loads neither PyBullet nor the perception pipeline, and ``python -m`` of one module does not import
it twice.
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> the module of this package that defines it
_API = {
    "Scene": "scenes",
    "SceneBuilder": "scenes",
    "random_scene": "scenes",
    "TABLE_TARGET": "render",
    "camera_specs": "render",
    "save_frame": "render",
    "table_camera": "render",
    "as_truth_ids": "eval",
    "evaluate": "eval",
    "evaluate_no_oracle": "eval",
    "format_report": "eval",
    "perceivable_prediction": "eval",
    "perceivable_truth": "eval",
    "procedural_scene": "eval",
    "skills_scene": "eval",
    "skills_scene_seen_open": "eval",
    "visible_nodes": "eval",
    "with_graph_attributes": "eval",
    "VISIBLE_PIXELS": "eval",
    "study": "views",
    "markdown": "views",
    "heldout_frames": "train_data",
    "run_training": "train_data",
    "training_frames": "train_data",
    "classify_errors": "node_errors",
}

__all__ = sorted(_API)


def __getattr__(name: str) -> Any:
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)
