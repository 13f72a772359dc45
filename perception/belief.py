"""Object permanence across observations: what a closed container hides is still there.

A camera cannot see a bowl inside a closed drawer. Perceiving each frame in isolation would drop it,
and a goal such as "the bowl in the bottom drawer, drawer closed" could never be verified. ``update_belief``
merges a new observation into the previous belief: every node seen now comes from the observation; a node
*not* seen now is kept, with its support edge and marked ``observed: False``, only when its absence is
explained — it was last inside (or on something inside) a container that is now observed closed, or (when
the frames of the observation are given) something nearer stands in front of where it was in every camera
that looks there (the robot's arm, a box's walls: :func:`occluded`), or its mask still shows a few pixels
(a glimpse too small to measure: :func:`glimpsed`). Any other disappearance is believed:
the object is gone from view for a reason we cannot explain, so it is dropped rather than invented.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from gsr.scene_graph import SUPPORT_RELATIONS, Edge, Node, SceneGraph

if TYPE_CHECKING:
    from gsr.perception.frame import Frame

#: Something this much nearer (m) than a remembered object's top, where the object would be in the
#: image, hides it; the margin keeps the object's own supporter (a plate under a cup) from counting.
OCCLUSION_MARGIN = 0.03


def _hidden_by_closed_container(node_id: str, belief: SceneGraph, observed: SceneGraph) -> bool:
    """True when, following support edges down from ``node_id`` in the belief, an ``in`` edge reaches a
    container that the new observation shows closed."""
    support = belief.supports()
    now = observed.node_map()
    seen: set[str] = set()
    current = node_id
    while current in support and current not in seen:
        seen.add(current)
        edge = support[current]
        target = now.get(edge.target)
        if edge.relation == "in" and target is not None and "closed" in target.states:
            return True
        current = edge.target
    return False


def occluded(node: Node, frames: Sequence[Frame], margin: float = OCCLUSION_MARGIN) -> bool:
    """True when no camera could have seen ``node`` where it was: at the centre of its box's top, every
    camera that has that point in its image measures something nearer by more than ``margin``.

    A point no camera has in its image counts as hidden too; a node without a box cannot be tested."""
    if node.bbox is None or not frames:
        return False
    lo, hi = node.bbox.min, node.bbox.max
    top = np.array([(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, hi.z])
    for f in frames:
        cam = f.camera
        rot, t = cam.cam_to_world[:3, :3], cam.cam_to_world[:3, 3]
        x, y, z = rot.T @ (top - t)  # OpenCV camera frame: z forward
        if z <= 0:
            continue
        u, v = round(float(cam.fx * x / z + cam.cx)), round(float(cam.fy * y / z + cam.cy))
        if not (0 <= u < cam.width and 0 <= v < cam.height):
            continue
        window = f.depth[max(v - 1, 0) : v + 2, max(u - 1, 0) : u + 2]
        valid = window[np.isfinite(window) & (window > 0)]
        if valid.size == 0 or float(valid.max()) >= z - margin:
            return False  # this camera sees as far as the object (or farther): it would have seen it
    return True


def glimpsed(frames: Sequence[Frame]) -> set[str]:
    """Ids whose instance mask covers at least one pixel in some frame (seen, if only a sliver)."""
    out: set[str] = set()
    for f in frames:
        for mask_id in np.unique(f.masks[f.masks >= 0]).tolist():
            label = f.labels.get(int(mask_id))
            if label is not None and label.id is not None:
                out.add(label.id)
    return out


def update_belief(
    belief: SceneGraph | None, observed: SceneGraph, frames: Sequence[Frame] = ()
) -> SceneGraph:
    """The new belief: the observation plus the occluded objects it explains (see the module docstring)."""
    if belief is None:
        return observed
    seen = {n.id for n in observed.nodes}
    slivers = glimpsed(frames) - seen
    kept: list[Node] = []
    for node in belief.nodes:
        if node.id in seen or node.parent is not None:
            continue
        if (
            node.id in slivers
            or _hidden_by_closed_container(node.id, belief, observed)
            or occluded(node, frames)
        ):
            kept.append(node.model_copy(update={"attributes": {**node.attributes, "observed": False}}))
    if not kept:
        return observed
    kept_ids = {n.id for n in kept}
    nodes = {n.id for n in observed.nodes} | kept_ids
    carried = [
        e
        for e in belief.edges
        if e.source in kept_ids
        and e.relation in SUPPORT_RELATIONS
        and e.target in nodes  # where it was last seen
    ]
    return observed.model_copy(
        update={
            "nodes": tuple(sorted((*observed.nodes, *kept), key=lambda n: n.id)),
            "edges": tuple(sorted({*observed.edges, *carried}, key=Edge.key)),
            "metadata": {**observed.metadata, "remembered": sorted(kept_ids)},
        }
    )
