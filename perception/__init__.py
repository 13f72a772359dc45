"""RGB-D to grounded scene graph (see docs/architecture.md and docs/perception.md). Depends on `gsr` only.

open3d is imported inside the functions that need it, so importing this package stays light.
"""

from gsr.perception.articulation import ArticulationThresholds
from gsr.perception.belief import update_belief
from gsr.perception.camera import (
    Camera,
    camera_from_dict,
    camera_from_gl,
    depth_from_gl_buffer,
    load_camera,
    near_far_from_projection,
    save_camera,
    split_gl_segmentation,
)
from gsr.perception.corrupt import add_depth_noise, erode_masks
from gsr.perception.evaluate import Score, score
from gsr.perception.frame import Detector, Frame, InstanceLabel, frame_from_detector, load_frame, load_labels
from gsr.perception.geometry import GeometryParams, back_project
from gsr.perception.pipeline import PerceptionParams, perceive, perceive_files
from gsr.perception.relations import RelationThresholds

__all__ = [
    "ArticulationThresholds",
    "Camera",
    "Detector",
    "Frame",
    "GeometryParams",
    "InstanceLabel",
    "PerceptionParams",
    "RelationThresholds",
    "Score",
    "add_depth_noise",
    "back_project",
    "camera_from_dict",
    "camera_from_gl",
    "depth_from_gl_buffer",
    "erode_masks",
    "frame_from_detector",
    "load_camera",
    "load_frame",
    "load_labels",
    "near_far_from_projection",
    "perceive",
    "perceive_files",
    "save_camera",
    "score",
    "split_gl_segmentation",
    "update_belief",
]
