"""The perception pipeline: frames (RGB-D + masks + labels + cameras) -> grounded ``SceneGraph``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from gsr.perception.articulation import ArticulationThresholds, keypoints, part_states
from gsr.perception.drawer_slots import hidden_drawers
from gsr.perception.frame import Frame, InstanceLabel, load_frame
from gsr.perception.geometry import (
    GeometryParams,
    Instance,
    back_project,
    color_name,
    fit_boxes,
    number_anonymous,
    support_plane,
)
from gsr.perception.inner import objects_in_containers, parts_read_on_objects, pieces_in_closed
from gsr.perception.instances import build_instances
from gsr.perception.relations import GROUND_CATEGORIES, RelationThresholds, descriptive_relations, supports
from gsr.perception.track import assign_parts, drop_wall_pieces

from gsr.categories import category_of
from gsr.errors import GSRError
from gsr.io import write_text_atomic
from gsr.scene_graph import BoundingBox, Edge, Keypoint, Node, Pose, SceneGraph, Vec3


@dataclass(frozen=True)
class PerceptionParams:
    """Everything tunable in one place; the defaults are the documented ones."""

    geometry: GeometryParams = field(default_factory=GeometryParams)
    relations: RelationThresholds = field(default_factory=RelationThresholds)
    articulation: ArticulationThresholds = field(default_factory=ArticulationThresholds)
    world_to_robot: tuple[tuple[float, ...], ...] | None = None  # 4x4; None: robot base = world origin
    descriptive: bool = True  # also infer adjacent / left_of / right_of / front_of / behind


def perceive(frames: Frame | list[Frame], params: PerceptionParams | None = None) -> SceneGraph:
    """Perceive one or more frames (fused across cameras) into a scene graph."""
    params = params or PerceptionParams()
    frame_list = [frames] if isinstance(frames, Frame) else list(frames)
    if not frame_list:
        raise GSRError("perceive: no frames given")
    instances, segments = build_instances(frame_list, params.geometry)
    plane = _ground_plane(instances, frame_list, params)
    assign_parts(
        instances, GROUND_CATEGORIES, params.geometry
    )  # detector parts (drawers, doors) get their objects
    instances += hidden_drawers(instances, frame_list)  # closed drawers no camera shows (no-oracle only)
    instances = drop_wall_pieces(instances, params.relations)  # one camera's wall bands in a container
    instances = objects_in_containers(instances)  # what stands in an open box, left in the box's segment
    instances = parts_read_on_objects(instances)  # one camera's view of a box read as a drawer
    world_to_robot = None if params.world_to_robot is None else np.asarray(params.world_to_robot, float)
    states = part_states(instances, params.articulation)
    closed = frozenset(k for k, (st, _) in states.items() if "closed" in st)
    support = supports(instances, plane, params.relations, closed)
    kept = pieces_in_closed(instances, support, closed)  # a closed box's own patch, seen by one camera
    if len(kept) < len(instances):
        instances = kept
        support = supports(instances, plane, params.relations, closed)
    kps = keypoints(instances, segments, params.articulation)
    edges = [(a, rel, b) for a, (rel, b) in support.items()]
    if params.descriptive:
        edges += descriptive_relations(instances, support, params.relations, world_to_robot)
    nodes = [_node(i, states.get(i.key), kps.get(i.key, [])) for i in instances]
    nodes = _with_drawer_levels(nodes + _missing_parents(nodes))
    ids = {n.id for n in nodes}
    kept_kps = sorted(k for k in kps if k not in ids)
    metadata = {
        "source": "perception",
        "frames": len(frame_list),
        "support_plane": None if plane is None else [round(float(v), 5) for v in plane],
    }
    if kept_kps:
        metadata["unattached_keypoints"] = kept_kps
    return SceneGraph(
        nodes=tuple(sorted(nodes, key=lambda n: n.id)),
        edges=tuple(Edge(source=a, relation=r, target=b) for a, r, b in sorted(set(edges))),
        metadata=metadata,
    )


def _ground_plane(
    instances: list[Instance], frames: list[Frame], params: PerceptionParams
) -> np.ndarray | None:
    """RANSAC support plane of the ground; finds (and names) the ground when no label gave it.

    Order: the labelled ground (table/floor); else the dominant plane of unlabelled background pixels;
    else the largest anonymous instance that is one horizontal plane (a detector's "table" segment).
    """
    grounds = [i for i in instances if i.label.category in GROUND_CATEGORIES]
    if grounds:
        return support_plane(_sample(np.concatenate([g.points for g in grounds])), params.geometry)
    pts = _sample(_background_points(frames, params.geometry))
    plane = support_plane(pts, params.geometry) if len(pts) >= params.geometry.min_points else None
    if plane is not None and abs(plane[2]) > _HORIZONTAL:
        inliers = pts[np.abs(pts @ plane[:3] + plane[3]) <= params.geometry.plane_distance]
        if len(inliers) >= params.geometry.min_points:
            table = Instance(
                "table", InstanceLabel(id="table", category="table"), inliers, _grey(len(inliers))
            )
            fit_boxes(table)
            instances.append(table)
            return plane
    anonymous = sorted(
        (i for i in instances if i.label.id is None), key=lambda i: -float(i.size[0] * i.size[1])
    )
    for cand in anonymous[:1]:
        plane = support_plane(_sample(cand.points), params.geometry)
        if plane is None or abs(plane[2]) < _HORIZONTAL:
            break
        on_plane = np.abs(cand.points @ plane[:3] + plane[3]) <= params.geometry.plane_distance
        if float(on_plane.mean()) >= 0.9:  # one flat horizontal surface: the ground
            cand.label = InstanceLabel(id="table", category="table")
            cand.key = "table"
            number_anonymous(instances)
            return plane
    return None


_HORIZONTAL = 0.95  # |normal z| of a plane that counts as horizontal (within ~18 degrees)


def _sample(pts: np.ndarray, n: int = 20000) -> np.ndarray:
    """At most ``n`` points (fixed seed): RANSAC needs a sample of the surface, not all of it."""
    return pts if len(pts) <= n else pts[np.random.default_rng(0).choice(len(pts), n, replace=False)]


def _background_points(frames: list[Frame], params: GeometryParams) -> np.ndarray:
    """World points of pixels that belong to no instance (where a table usually is)."""
    chunks = []
    for f in frames:
        pts = back_project(f.depth, f.camera, params.stride).reshape(-1, 3)
        bg = (f.masks[:: params.stride, :: params.stride] < 0).reshape(-1)
        chunks.append(pts[bg & np.all(np.isfinite(pts), axis=1)])
    return np.concatenate(chunks) if chunks else np.zeros((0, 3))


def _grey(n: int) -> np.ndarray:
    return np.full((n, 3), 128, dtype=np.uint8)


def _node(inst: Instance, state: tuple[tuple[str, ...], dict[str, float]] | None, kps: list) -> Node:
    label = inst.label
    category = label.category
    attributes: dict[str, str | float | int | bool] = {}
    if category == "thing" and label.id is not None:  # a node id without category: parse the name
        category, parsed = category_of(label.id)
        attributes.update(parsed)
    attributes.update({k: v for k, v in label.attributes.items() if isinstance(v, str | float | int | bool)})
    attributes["color"] = label.color or attributes.get("color") or color_name(inst.rgb)
    attributes.update(
        size_x=round(float(inst.size[0]), 4),
        size_y=round(float(inst.size[1]), 4),
        size_z=round(float(inst.size[2]), 4),
        points=len(inst.points),
        views=inst.views,
    )
    states: tuple[str, ...] = ()
    if state is not None:
        states = state[0]
        attributes.update(state[1])
    half = inst.yaw / 2.0
    pose = Pose(
        position=Vec3(x=float(inst.center[0]), y=float(inst.center[1]), z=float(inst.center[2])),
        orientation=(0.0, 0.0, math.sin(half), math.cos(half)),
    )
    bbox = BoundingBox(min=Vec3(**_xyz(inst.aabb_min)), max=Vec3(**_xyz(inst.aabb_max)))
    keypoints_ = tuple(Keypoint(name=n, position=Vec3(**_xyz(p))) for n, p in kps)
    return Node(
        id=inst.key,
        category=category,
        attributes=attributes,
        states=states,
        parent=label.parent,
        keypoints=keypoints_,
        pose=pose,
        bbox=bbox,
    )


def _xyz(v: np.ndarray) -> dict[str, float]:
    return {"x": round(float(v[0]), 5), "y": round(float(v[1]), 5), "z": round(float(v[2]), 5)}


def _with_drawer_levels(nodes: list[Node]) -> list[Node]:
    """Rank each parent's drawers by height (0 = lowest), as the task graph's ``level`` attribute does.

    Instructions name drawers by rank ("the bottom drawer"), so the level is perceived from geometry
    (the drawers' centres) rather than taken from a label; a level the label already gives is kept.
    """
    drawers: dict[str, list[Node]] = {}
    for n in nodes:
        if n.parent is not None and n.category == "drawer" and n.pose is not None:
            drawers.setdefault(n.parent, []).append(n)
    level: dict[str, int] = {}
    for group in drawers.values():
        for rank, n in enumerate(sorted(group, key=lambda d: d.pose.position.z)):  # type: ignore[union-attr]
            level[n.id] = rank
    return [
        n.model_copy(update={"attributes": {**n.attributes, "level": level[n.id]}})
        if n.id in level and "level" not in n.attributes
        else n
        for n in nodes
    ]


def _missing_parents(nodes: list[Node]) -> list[Node]:
    """Nodes for parents named by parts but not seen themselves (category parsed from the id)."""
    ids = {n.id for n in nodes}
    out: list[Node] = []
    for n in nodes:
        if n.parent is not None and n.parent not in ids:
            category, attrs = category_of(n.parent)
            out.append(Node(id=n.parent, category=category, attributes={**attrs, "observed": False}))
            ids.add(n.parent)
    return out


def perceive_files(
    rgb: str | Path,
    depth: str | Path,
    masks: str | Path,
    camera: str | Path,
    labels: str | Path | None = None,
    out: str | Path | None = None,
    params: PerceptionParams | None = None,
) -> SceneGraph:
    """Perceive one frame given as files; with ``out``, write the graph JSON there atomically."""
    graph = perceive(load_frame(rgb, depth, masks, camera, labels), params)
    if out is not None:
        write_text_atomic(Path(out), graph.to_json() + "\n")
    return graph
