"""Frames -> instances: per-camera clouds merged by node id, anonymous segments fused across cameras.

``build_instances`` is the multi-view step between the per-instance geometry (``geometry``: clouds,
cleaning, boxes) and the scene graph (``pipeline``). It sits above both ``geometry`` and the cross-camera
fusion (``track.fuse_views``: 3D overlap, category vote), so ``geometry`` imports neither.
"""

from __future__ import annotations

import numpy as np
from gsr.perception.frame import Frame, InstanceLabel
from gsr.perception.geometry import GeometryParams, Instance, clean_points, fit_boxes, instance_clouds
from gsr.perception.track import fuse_views


def build_instances(frames: list[Frame], params: GeometryParams) -> tuple[list[Instance], list[Instance]]:
    """Fused, cleaned instances over all frames, and keypoint segments (labels with ``keypoint_of``)."""
    objects: dict[str, Instance] = {}
    keypoints: dict[str, Instance] = {}
    unlabeled: list[Instance] = []
    for fi, frame in enumerate(frames):
        for mask_id, (pts, rgb) in instance_clouds(frame, params).items():
            label = frame.labels.get(mask_id, InstanceLabel())
            if label.ignore:
                continue
            if label.keypoint_of is not None:
                key = f"{label.keypoint_of}#{label.name}"
                _merge(keypoints, key, label, pts, rgb)
            elif label.id is not None:
                _merge(objects, label.id, label, pts, rgb)
            else:
                unlabeled.append(Instance(f"{label.category}_f{fi}m{mask_id}", label, pts, rgb))
    out: list[Instance] = []
    for inst in objects.values():
        if _finish(inst, params):
            out.append(inst)
    anonymous: list[Instance] = []
    for inst in unlabeled:
        if _finish(inst, params):
            anonymous.append(inst)
    out.extend(fuse_views(anonymous, params))
    kps = [k for k in keypoints.values() if _finish(k, params)]
    return out, kps


def _merge(
    into: dict[str, Instance], key: str, label: InstanceLabel, pts: np.ndarray, rgb: np.ndarray
) -> None:
    if key in into:
        prev = into[key]
        prev.points = np.concatenate((prev.points, pts))
        prev.rgb = np.concatenate((prev.rgb, rgb))
        prev.views += 1
    else:
        into[key] = Instance(key, label, pts, rgb)


def _finish(inst: Instance, params: GeometryParams) -> bool:
    inst.points, inst.rgb = clean_points(inst.points, inst.rgb, params)
    if len(inst.points) < params.min_points:
        return False
    fit_boxes(inst)
    return True
