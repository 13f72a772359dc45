"""The PyBullet world: table, rail-mounted Panda and procedural objects built from a TaskSpec's layout.

``build_world(task_or_layout, seed)`` is deterministic: the same task and seed give the same bodies,
poses and joint states. Scene-graph node ids map to bodies (objects) and links (parts such as
``wooden_cabinet_1/top_drawer``); :meth:`World.locate` resolves any node id. Always headless
(``p.DIRECT``); buttons latch their owner's on/off state as they are pressed, inside :meth:`World.step`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from gsr.skills.asset_model import Articulation, AssetModel, Interior
from gsr.skills.robot import Robot

from gsr.errors import GSRError
from gsr.scene_graph import SceneGraph
from gsr.task_spec import Layout, PlacedObject, Region

SETTLE_STEPS = 120
#: Joint friction that keeps articulated parts where they are left (N or N m).
JOINT_FRICTION = {"drawer": 4.0, "lid": 1.5, "door": 0.6, "knob": 0.15}


@dataclass
class SimObject:
    """One loaded object: its body, model and link indices by link name (base = -1)."""

    id: str
    body: int
    model: AssetModel
    placed: PlacedObject
    links: dict[str, int]


@dataclass(frozen=True, slots=True)
class Located:
    """Where a node lives in the simulator: an object, the asset part (or ``""``), the body and link."""

    object_id: str
    part: str
    body: int
    link: int


@dataclass
class World:
    """A built simulation: the client, the robot, the objects and the scene graph they realise."""

    client: int
    robot: Robot
    table_body: int
    table_id: str
    graph: SceneGraph
    layout: Layout
    seed: int
    objects: dict[str, SimObject] = field(default_factory=dict)
    parts: dict[str, tuple[str, str]] = field(default_factory=dict)  # part node id -> (object id, asset part)
    regions: dict[str, Region] = field(default_factory=dict)
    powered: dict[str, bool] = field(default_factory=dict)  # switchable object id -> on
    _pressed: dict[tuple[str, str], bool] = field(default_factory=dict)
    sim_steps: int = 0
    #: debugging only (off by default, never used by benchmarks): weld a grasped object to the hand
    debug_weld: bool = False
    welds: dict[str, int] = field(default_factory=dict)  # object id -> constraint id (debug_weld only)
    #: objects moved apart at build time because the layout's positions overlap our assets (id -> dx, dy)
    adjusted: dict[str, tuple[float, float]] = field(default_factory=dict)

    # ------------------------------------------------------------ lookup

    def locate(self, node_id: str) -> Located:
        """The body/link of a node; GSRError naming the node if it has no physical counterpart."""
        if node_id in self.objects:
            o = self.objects[node_id]
            return Located(node_id, "", o.body, -1)
        if node_id in self.parts:
            obj_id, part = self.parts[node_id]
            o = self.objects[obj_id]
            link = self.part_link(obj_id, part)
            return Located(obj_id, part, o.body, link)
        if node_id == self.table_id or node_id in self.regions:
            return Located(self.table_id, "", self.table_body, -1)
        raise GSRError(f"node {node_id!r} has no body in the simulated world")

    def interior_of(self, node_id: str) -> tuple[SimObject, str, Interior] | None:
        """The object, part name and interior behind a container node (a box, a drawer); None when the
        node is no object or part, or has no interior."""
        if node_id in self.objects:
            o, part = self.objects[node_id], ""
        elif node_id in self.parts:
            obj_id, part = self.parts[node_id]
            o = self.objects[obj_id]
        else:
            return None
        interior = o.model.interiors.get(part)
        return (o, part, interior) if interior is not None else None

    def part_link(self, object_id: str, part: str) -> int:
        """Link index of an asset part (articulation, interior or plain part link); -1 for the base."""
        o = self.objects[object_id]
        m = o.model
        if part in m.articulations:
            return o.links[m.articulations[part].link]
        if part in m.interiors:
            return o.links[m.interiors[part].link]
        if part in m.part_links:
            return o.links[m.part_links[part]]
        return -1

    def link_owner(self, body: int, link: int) -> tuple[str, list[str]] | None:
        """Who a PyBullet (body, link) pair belongs to, the inverse of :meth:`locate`: the object's node id
        and the part nodes whose link it is, in the order of ``parts`` (none for the base link, -1); the
        table body is ``(table_id, [])``; None for any other body (the robot, the floor). Callers choose
        among the parts: a mask takes any part (a handle's pixels are the handle), a contact only a
        supporter or container part (a handle supports nothing)."""
        if body == self.table_body:
            return self.table_id, []
        for o in self.objects.values():
            if o.body != body:
                continue
            if link < 0:
                return o.id, []
            parts = [
                nid
                for nid, (obj, part) in self.parts.items()
                if obj == o.id and part and self.part_link(obj, part) == link
            ]
            return o.id, parts
        return None

    def articulation(self, node_id: str, role: str) -> tuple[SimObject, str, Articulation] | None:
        """The articulation a node's ``open`` (role ``open``) or ``turn on`` (role ``switch``) acts on."""
        loc = self.locate(node_id)
        if loc.object_id == self.table_id:
            return None
        o = self.objects[loc.object_id]
        part = loc.part or (o.model.open_part if role == "open" else o.model.switch_part) or ""
        art = o.model.articulations.get(part)
        return (o, part, art) if art is not None else None

    def joint_position(self, obj: SimObject, part: str) -> float:
        """Current joint position of an articulated part."""
        import pybullet as p

        link = obj.links[obj.model.articulations[part].link]
        return float(p.getJointState(obj.body, link, physicsClientId=self.client)[0])

    def joint_axis(self, obj: SimObject, part: str) -> np.ndarray:
        """Unit world direction in which an articulated part's joint opens (prismatic parts)."""
        import pybullet as p

        art = obj.model.articulations[part]
        info = p.getJointInfo(obj.body, obj.links[art.link], physicsClientId=self.client)
        _, orn = self.link_pose(obj.body, info[16])
        rot = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
        a = rot @ np.array(info[13])
        return a / np.linalg.norm(a) * (1 if art.open > art.closed else -1)

    def link_pose(self, body: int, link: int) -> tuple[np.ndarray, np.ndarray]:
        """World position and quaternion of a link frame (the base for -1)."""
        import pybullet as p

        if link < 0:
            # PyBullet reports the base's centre of mass; undo the inertial offset to get the URDF frame
            com, orn = p.getBasePositionAndOrientation(body, physicsClientId=self.client)
            local = p.getDynamicsInfo(body, -1, physicsClientId=self.client)
            inv = p.invertTransform(local[3], local[4])
            pos, orn = p.multiplyTransforms(com, orn, inv[0], inv[1])
        else:
            s = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=self.client)
            pos, orn = s[4], s[5]
        return np.array(pos), np.array(orn)

    def to_world(self, body: int, link: int, local: tuple[float, float, float]) -> np.ndarray:
        """A point given in a link's frame, in world coordinates."""
        import pybullet as p

        pos, orn = self.link_pose(body, link)
        return np.array(p.multiplyTransforms(pos, orn, local, (0, 0, 0, 1))[0])

    def yaw_of(self, body: int, link: int = -1) -> float:
        """Heading (rad) of a link's x axis in the world."""
        import pybullet as p

        _, orn = self.link_pose(body, link)
        return float(p.getEulerFromQuaternion(orn)[2])

    def aabb(self, body: int, link: int = -1) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box of a link (the base for -1)."""
        import pybullet as p

        lo, hi = p.getAABB(body, link, physicsClientId=self.client)
        return np.array(lo), np.array(hi)

    def body_aabb(self, body: int) -> tuple[np.ndarray, np.ndarray]:
        """AABB over all links of a body."""
        import pybullet as p

        boxes = [
            self.aabb(body, link) for link in range(-1, p.getNumJoints(body, physicsClientId=self.client))
        ]
        return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)

    # ------------------------------------------------------------ stepping

    def step(self, n: int = 1) -> None:
        """Advance the simulation ``n`` steps (1/240 s each), latching button presses."""
        import pybullet as p

        for _ in range(n):
            p.stepSimulation(physicsClientId=self.client)
            self.sim_steps += 1
            self._latch_buttons()

    def _latch_buttons(self) -> None:
        for o in self.objects.values():
            for part, art in o.model.articulations.items():
                if art.kind != "button":
                    continue
                frac = (self.joint_position(o, part) - art.closed) / (art.open - art.closed)
                key = (o.id, part)
                if frac > 0.7 and not self._pressed.get(key):
                    self._pressed[key] = True
                    self.powered[o.id] = not self.powered.get(o.id, False)
                elif frac < 0.3:
                    self._pressed[key] = False

    def is_on(self, object_id: str) -> bool:
        """Whether a switchable object is on: its knob past half-turn, or its button-latched state."""
        o = self.objects[object_id]
        part = o.model.switch_part
        if part is None:
            return False
        art = o.model.articulations[part]
        if art.kind == "button":
            return self.powered.get(object_id, False)
        return art.is_open(self.joint_position(o, part))

    def close(self) -> None:
        """Disconnect the physics client."""
        import pybullet as p

        if p.isConnected(self.client):
            p.disconnect(self.client)

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = [
    "JOINT_FRICTION",
    "SETTLE_STEPS",
    "Located",
    "SimObject",
    "World",
]
