"""Ground-truth scene graphs from simulator state, and a graph for a bare layout.

:func:`scene_graph_from_sim` keeps the task graph's node ids, categories and attributes and recomputes
everything physical: ``in`` = at least half of the object's bounding box lies inside a container's
interior volume *and* the object sits inside the walls (its bottom below the rim), or it rests on something
that is itself in that container (a cube stacked on a cube in a tray); ``on`` = a support contact (normal pointing up from the supporter, strongest contact
wins; on a table inside a named region, the region); ``held`` = touched by both fingers; open/closed
and on/off from joint positions and button latches; poses, boxes and keypoints from the links.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from gsr.skills.assets import make_asset

from gsr.categories import category_of, is_a
from gsr.facts import node_affordances
from gsr.scene_graph import BoundingBox, Edge, Keypoint, Node, Pose, SceneGraph, Vec3
from gsr.task_spec import Layout

if TYPE_CHECKING:
    from gsr.skills.world import World

IN_RATIO = 0.5
#: An object whose bottom is no more than this below a container's rim rests *on* the rim, not in it.
#: Open containers' interior volumes reach 1.5x their height (skills/assets.py, so tall bottles in a
#: basket count), which alone would put a box resting on another box's rim "in" the lower box.
RIM_TOLERANCE = 0.01


def _v(a: np.ndarray | tuple[float, ...]) -> Vec3:
    return Vec3(x=round(float(a[0]), 4), y=round(float(a[1]), 4), z=round(float(a[2]), 4))


def _overlap_ratio(lo: np.ndarray, hi: np.ndarray, blo: np.ndarray, bhi: np.ndarray) -> float:
    inter = np.clip(np.minimum(hi, bhi) - np.maximum(lo, blo), 0, None)
    vol = float(np.prod(np.maximum(hi - lo, 1e-6)))
    return float(np.prod(inter)) / vol


def interior_boxes(world: World) -> list[tuple[str, np.ndarray, np.ndarray, float]]:
    """Container volumes as world AABBs: (node id, min, max, volume), smallest first."""
    return [(nid, lo, hi, vol) for nid, lo, hi, vol, _ in container_volumes(world)]


def container_volumes(world: World) -> list[tuple[str, np.ndarray, np.ndarray, float, float]]:
    """Container volumes as world AABBs with the rim: (node id, min, max, volume, rim z), smallest first.

    The rim is the top of the link that carries the interior (a box's walls, a drawer's tray), capped by
    the interior's own top (a microwave's cavity ends below its roof)."""
    out = []
    nodes = world.graph.node_map()
    owners: dict[tuple[str, str], str] = {(obj, part): nid for nid, (obj, part) in world.parts.items()}
    for o in world.objects.values():
        for part, interior in o.model.interiors.items():
            node_id = o.id if part == "" else owners.get((o.id, part))
            if node_id is None or node_id not in nodes or "container" not in node_affordances(nodes[node_id]):
                continue
            link = o.links[interior.link]
            c, s = np.array(interior.center), np.array(interior.size) / 2
            corners = [
                world.to_world(o.body, link, tuple(c + s * np.array(d)))
                for d in np.ndindex(2, 2, 2)
                for d in [np.array(d) * 2 - 1]
            ]
            lo, hi = np.min(corners, axis=0), np.max(corners, axis=0)
            rim = min(float(world.aabb(o.body, link)[1][2]), float(hi[2]))
            out.append((node_id, lo, hi, float(np.prod(hi - lo)), rim))
    return sorted(out, key=lambda t: t[3])


def _centre_inside(world: World, node_id: str, point: np.ndarray) -> bool:
    """Whether ``point`` lies over the container's interior footprint in the interior's own frame (a box
    turned by 45 degrees has a world bounding box half again as wide as itself)."""
    import pybullet as p

    found = world.interior_of(node_id)
    if found is None:
        return True
    o, _, interior = found
    pos, orn = world.link_pose(o.body, o.links[interior.link])
    inv = p.invertTransform(tuple(pos), tuple(orn))
    local = np.array(p.multiplyTransforms(inv[0], inv[1], tuple(point), (0, 0, 0, 1))[0])
    half = np.array(interior.size[:2]) / 2 + RIM_TOLERANCE
    return bool(np.all(np.abs(local[:2] - np.array(interior.center[:2])) <= half))


def _link_node(world: World, body: int, link: int) -> str | None:
    """The graph node a contact on (body, link) belongs to: a supporter or container part node if the link
    is one, else the object (the table only when the graph has it)."""
    owner = world.link_owner(body, link)
    if owner is None:
        return None
    obj, parts = owner
    for nid in parts:
        if world.graph.has_node(nid):
            aff = node_affordances(world.graph.node(nid))
            if "supporter" in aff or "container" in aff:
                return nid
    if body == world.table_body and not world.graph.has_node(obj):
        return None
    return obj


def _region_of(world: World, pos: np.ndarray) -> str | None:
    for nid, r in world.regions.items():
        if not world.graph.has_node(nid):
            continue
        x0, y0, x1, y1 = r.bounds
        if x0 <= pos[0] <= x1 and y0 <= pos[1] <= y1:
            return nid
    return None


def support_of(
    world: World, object_id: str, boxes: list | None = None, _depth: int = 0
) -> tuple[str, str] | None:
    """``("in" | "on", node)`` supporting an object now, ``("held", "")`` in the gripper, or None (in flight).

    ``boxes``: :func:`container_volumes` of the world (computed when None; ``[]`` skips containment)."""
    import pybullet as p

    o = world.objects[object_id]
    robot = world.robot
    fingers = {pt[4] for pt in p.getContactPoints(o.body, robot.body, physicsClientId=world.client)}
    if set(robot.fingers) <= fingers:
        return ("held", "")
    vols = boxes if boxes is not None else container_volumes(world)
    lo, hi = world.body_aabb(o.body)
    above_rim: set[str] = set()  # containers the object overlaps while resting above their rim
    for node_id, blo, bhi, _, rim in vols:
        if node_id.split("/")[0] == object_id or _overlap_ratio(lo, hi, blo, bhi) < IN_RATIO:
            continue
        if not _centre_inside(world, node_id, (lo + hi) / 2):
            continue  # beside a turned box, inside its world-aligned bounding box only
        if lo[2] < rim - RIM_TOLERANCE:
            return ("in", node_id)
        above_rim.add(node_id)
    own = [(blo, bhi) for node_id, blo, bhi, _, _ in vols if node_id.split("/")[0] == object_id]
    contact = _contact_support(world, object_id, lo, hi, own)
    if contact is not None and above_rim and contact[1] in world.objects and _depth < 4:
        # stacked on something that is in the container (a cube on a cube in a tray): in it too
        below = support_of(world, contact[1], vols, _depth + 1)
        if below is not None and below[0] == "in" and below[1] in above_rim:
            return below
    return contact


def _contact_support(
    world: World, object_id: str, lo: np.ndarray, hi: np.ndarray, own: list[tuple[np.ndarray, np.ndarray]]
) -> tuple[str, str] | None:
    """``("on", node)`` for the strongest upward support contact (a table region for the table), or None.

    ``own``: the object's interior volumes; what lies in them is its content, never its support (a book
    standing in a lidded box touches the lid from below)."""
    import pybullet as p

    o = world.objects[object_id]
    force: dict[str, float] = {}
    contents: dict[int, bool] = {}
    for pt in p.getContactPoints(bodyA=o.body, physicsClientId=world.client):
        other, link, normal_on_b, f = pt[2], pt[4], pt[7], pt[9]
        if other == world.robot.body or normal_on_b[2] < 0.5:
            continue
        if own and other not in contents:
            olo, ohi = world.body_aabb(other)
            contents[other] = any(_overlap_ratio(olo, ohi, blo, bhi) >= IN_RATIO for blo, bhi in own)
        if contents.get(other):
            continue
        node = _link_node(world, other, link)
        if node is not None and node != object_id:
            force[node] = force.get(node, 0.0) + f
    if not force:
        return None
    best = max(sorted(force), key=lambda k: force[k])
    if best == world.table_id:
        region = _region_of(world, (lo + hi) / 2)
        if region is not None:
            return ("on", region)
    return ("on", best)


def _states(world: World, node: Node) -> set[str]:
    states = set(node.states) - {"open", "closed", "on", "off", "held"}
    aff = node_affordances(node)
    obj_id, part = (node.id, "") if node.id in world.objects else world.parts.get(node.id, ("", ""))
    if not obj_id:
        return states
    o = world.objects[obj_id]
    if "openable" in aff:
        op = part or o.model.open_part
        if op in o.model.articulations:
            states.add("open" if o.model.articulations[op].is_open(world.joint_position(o, op)) else "closed")
    if "switchable" in aff or ("pressable" in aff and node.states):
        states.add("on" if world.is_on(obj_id) else "off")
    return states


def _node_geometry(world: World, node: Node) -> dict:
    try:
        loc = world.locate(node.id)
    except Exception:
        return {}
    if loc.object_id == world.table_id and node.id != world.table_id:
        r = world.regions.get(node.id)
        if r is None:
            return {}
        z = world.layout.table_height
        return {
            "bbox": BoundingBox(min=_v((r.bounds[0], r.bounds[1], z)), max=_v((r.bounds[2], r.bounds[3], z)))
        }
    pos, orn = world.link_pose(loc.body, loc.link)
    lo, hi = world.body_aabb(loc.body) if loc.link < 0 and loc.part == "" else world.aabb(loc.body, loc.link)
    out: dict = {
        "pose": Pose(position=_v(pos), orientation=tuple(round(float(v), 5) for v in orn)),
        "bbox": BoundingBox(min=_v(lo), max=_v(hi)),
    }
    if loc.object_id in world.objects:
        o = world.objects[loc.object_id]
        kps = []
        for name, (link_name, xyz) in sorted(o.model.keypoints.items()):
            owner = name.split("/")[0] if "/" in name else ""
            if (loc.part or "") != owner and not (loc.part == "" and owner == ""):
                continue
            kp = world.to_world(o.body, o.links[link_name], xyz)
            kps.append(Keypoint(name=name.split("/")[-1], position=_v(kp)))
        if kps:
            out["keypoints"] = tuple(kps)
    return out


def scene_graph_from_sim(world: World) -> SceneGraph:
    """The ground-truth scene graph of the world now: same node ids as the task graph, physical relations."""
    boxes = container_volumes(world)
    edges: list[Edge] = []
    held: set[str] = set()
    for oid, o in world.objects.items():
        if not world.graph.has_node(oid) or o.placed.fixed or o.model.fixed:
            # fixtures keep the support the task states (a cabinet stays on its table)
            edges += [e for e in world.graph.edges_from(oid) if e.relation in ("on", "in")]
            continue
        sup = support_of(world, oid, boxes)
        if sup is None:
            continue
        rel, target = sup
        if rel == "held":
            held.add(oid)
        elif world.graph.has_node(target):
            edges.append(Edge(source=oid, relation=rel, target=target))
    nodes = []
    for n in world.graph.nodes:
        states = _states(world, n)
        if n.id in held:
            states.add("held")
        nodes.append(n.model_copy(update={"states": tuple(sorted(states)), **_node_geometry(world, n)}))
    return SceneGraph(
        nodes=tuple(nodes), edges=tuple(edges), metadata={"source": "pybullet", "seed": world.seed}
    )


def graph_from_layout(layout: Layout, table_id: str = "table") -> SceneGraph:
    """A scene graph for a bare layout: objects (category from the asset name), asset parts, on/in edges."""
    nodes = [Node(id=table_id, category="table")]
    edges = []
    for o in layout.objects:
        category, attrs = category_of(o.asset)
        attrs = {k: v for k, v in attrs.items() if k != "level"}
        if o.color:
            attrs["color"] = o.color
        model = make_asset(o.asset, o.size, o.color)
        nodes.append(Node(id=o.id, category=category, attributes=attrs))
        for part in sorted(model.articulations):
            if part.startswith("drawer_"):
                level = int(part.split("_")[1])
                nodes.append(
                    Node(
                        id=f"{o.id}/{part}",
                        category="drawer",
                        parent=o.id,
                        attributes={"level": level},
                        states=("closed",),
                    )
                )
        if "top_side" in model.part_links:
            nodes.append(Node(id=f"{o.id}/top_side", category="cabinet_top", parent=o.id))
        for part in sorted(model.interiors):
            if part.startswith("compartment_"):
                nodes.append(Node(id=f"{o.id}/{part}", category="compartment", parent=o.id))
    ids = {n.id for n in nodes}
    cats = {n.id: n for n in nodes}
    for o in layout.objects:
        target = o.on or table_id
        if target not in ids:
            continue
        tnode = cats[target]
        aff = node_affordances(tnode)
        rel = "in" if "container" in aff and not is_a(tnode.category, "table") else "on"
        edges.append(Edge(source=o.id, relation=rel, target=target))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges))
