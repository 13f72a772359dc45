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

from gsr.scene_graph import SUPPORT_RELATIONS, Edge, Node, SceneGraph, Vec3

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


#: Cameras that must have seen an object in a container (when its look had that many) for it to be
#: remembered there once unseen: one camera's segment alone is as often a piece of the container's walls
#: or of what stands in it (a fragment) as an object, and a fragment remembered is a false ``in``.
CONFIRM_VIEWS = 2


def _confirmed(node: Node, belief: SceneGraph) -> bool:
    """The node was seen by ``CONFIRM_VIEWS`` cameras in the look it was last seen in (by all of them when
    that look had fewer); a node that carries no camera count (labelled or hand-built) counts as seen."""
    views = node.attributes.get("views")
    if not isinstance(views, int) or isinstance(views, bool):
        return True
    frames = belief.metadata.get("frames")
    cameras = frames if isinstance(frames, int) and frames > 0 else 1
    return views >= min(CONFIRM_VIEWS, cameras)


def occluded(node: Node, frames: Sequence[Frame], margin: float = OCCLUSION_MARGIN) -> bool:
    """True when no camera could have seen ``node`` where it was: at the centre of its box's top, every
    camera that has that point in its image measures something nearer by more than ``margin``.

    A point no camera has in its image counts as hidden too; a node without a box cannot be tested."""
    if node.bbox is None or not frames:
        return False
    lo, hi = node.bbox.min, node.bbox.max
    top = np.array([(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, hi.z])
    for f in frames:
        us, vs, zs, inside = f.camera.project(top[None, :])
        if not inside[0]:
            continue  # behind the camera or outside its image
        u, v, z = int(us[0]), int(vs[0]), float(zs[0])
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


def with_flush_parts(observed: SceneGraph, belief: SceneGraph | None) -> tuple[SceneGraph, SceneGraph | None]:
    """The belief's parts (drawers, doors) of objects seen now that have no segment now, believed closed.

    A drawer pushed shut is flush with its cabinet's front: cameras then often see no drawer at all, only
    the cabinet. A part perceived before, whose object is perceived now and which itself is not, is
    believed closed (an open drawer stands out of its cabinet and is seen). Returns ``observed`` plus those
    parts (``observed: False``, state ``closed``) and the belief in which a drawer that was seen open has
    been pushed back by its measured opening (``open_distance``) towards its object, with everything
    that was in it: what was seen in the drawer stays remembered there (:func:`update_belief`). A drawer
    that is segmented now (the tracker kept its id) whose measured opening changed carries what was in it
    by that change: pushed shut but seen as a flush front, its contents are where the drawer now is."""
    if belief is None:
        return observed, belief
    seen = observed.node_map()
    old = belief.node_map()
    shifts: dict[str, np.ndarray] = {}
    kept: list[Node] = []
    for n in belief.nodes:
        if n.parent is None or n.parent not in seen:
            continue
        now = seen.get(n.id)
        # a drawer seen now (same id) whose opening changed moved its contents by the change
        shift = _travel(n, old.get(n.parent), _opening(now))
        if shift is not None:
            shifts[n.id] = shift
        if now is not None:
            continue
        attrs = {**n.attributes, "observed": False}
        if "open_distance" in attrs:
            attrs["open_distance"] = 0.0
        kept.append(
            _moved(n, shifts.get(n.id)).model_copy(
                update={
                    "states": (*(s for s in n.states if s not in ("open", "closed")), "closed"),
                    "attributes": attrs,
                }
            )
        )
    if kept:
        observed = observed.model_copy(
            update={"nodes": tuple(sorted((*observed.nodes, *kept), key=lambda n: n.id))}
        )
    if not shifts:
        return observed, belief
    support = belief.supports()

    def container_of(node_id: str) -> str | None:
        visited: set[str] = set()
        while node_id in support and node_id not in visited:
            visited.add(node_id)
            edge = support[node_id]
            if edge.relation == "in" and edge.target in shifts:
                return edge.target
            node_id = edge.target
        return None

    moved = []
    for n in belief.nodes:
        c = container_of(n.id) if n.parent is None else None
        moved.append(_moved(n, shifts[c]) if c is not None else n)
    return observed, belief.model_copy(update={"nodes": tuple(moved)})


#: A drawer's measured opening must change by this much (m) before its contents are moved with it.
TRAVEL_MIN = 0.01


def _opening(part: Node | None) -> float | None:
    """A drawer's opening: its measured ``open_distance`` when perceived open, 0 when closed or no longer
    segmented (None), None when not measured. A closed drawer's measured opening is noise (its front is
    flush with the object's); only a change of state or of an open drawer's opening moves it."""
    if part is None or "closed" in part.states:
        return 0.0
    d = part.attributes.get("open_distance")
    return float(d) if isinstance(d, int | float) and not isinstance(d, bool) else None


def _travel(part: Node, parent: Node | None, opening_now: float | None) -> np.ndarray | None:
    """How a drawer seen open moved since: by the change of its opening (:func:`_opening`; ``opening_now``
    0 for a drawer pushed shut), along the side of its object's box it stands out of
    (the dominant axis of the part's offset from the object's centre). None when it did not move or
    cannot be told."""
    before = _opening(part)
    if part.category != "drawer" or before is None or before <= 0 or opening_now is None:
        return None
    change = opening_now - before
    if abs(change) < TRAVEL_MIN or parent is None or parent.bbox is None or part.bbox is None:
        return None
    pc, oc = _bbox_center(part), _bbox_center(parent)
    half = np.maximum((_bbox_size(parent) / 2.0)[:2], 1e-6)
    ratio = (pc - oc)[:2] / half
    k = int(np.argmax(np.abs(ratio)))
    axis = np.zeros(3)
    axis[k] = 1.0 if ratio[k] >= 0 else -1.0
    return change * axis


def _bbox_center(n: Node) -> np.ndarray:
    lo, hi = n.bbox.min, n.bbox.max  # type: ignore[union-attr]
    return np.array([(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, (lo.z + hi.z) / 2])


def _bbox_size(n: Node) -> np.ndarray:
    lo, hi = n.bbox.min, n.bbox.max  # type: ignore[union-attr]
    return np.array([hi.x - lo.x, hi.y - lo.y, hi.z - lo.z])


def _moved(n: Node, shift: np.ndarray | None) -> Node:
    """The node with its pose, box and keypoints translated by ``shift``."""
    if shift is None:
        return n

    def mv(v: Vec3) -> Vec3:
        return Vec3(
            x=round(v.x + float(shift[0]), 5),
            y=round(v.y + float(shift[1]), 5),
            z=round(v.z + float(shift[2]), 5),
        )

    update: dict = {}
    if n.pose is not None:
        update["pose"] = n.pose.model_copy(update={"position": mv(n.pose.position)})
    if n.bbox is not None:
        update["bbox"] = n.bbox.model_copy(update={"min": mv(n.bbox.min), "max": mv(n.bbox.max)})
    if n.keypoints:
        update["keypoints"] = tuple(k.model_copy(update={"position": mv(k.position)}) for k in n.keypoints)
    return n.model_copy(update=update)


def update_belief(
    belief: SceneGraph | None, observed: SceneGraph, frames: Sequence[Frame] = ()
) -> SceneGraph:
    """The new belief: the observation plus the occluded objects it explains (see the module docstring)."""
    if belief is None:
        return observed
    seen = {n.id for n in observed.nodes}
    slivers = glimpsed(frames) - seen
    contained = {e.source for e in belief.edges if e.relation == "in"}
    kept: list[Node] = []
    for node in belief.nodes:
        if node.id in seen or node.parent is not None:
            continue
        if (
            node.id in slivers
            or _hidden_by_closed_container(node.id, belief, observed)
            or occluded(node, frames)
        ):
            if node.id in contained and not _confirmed(node, belief):
                continue  # one camera's segment in a container: as often a piece of it as an object
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
