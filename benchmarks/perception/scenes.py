"""Random tabletop scenes rendered in PyBullet with exact ground-truth scene graphs, for perception.

A scene is built from primitive shapes at known poses (every object placed exactly at rest on its
supporter, so no physics step is needed): a table, cubes (some stacked), plates with things on them,
open boxes with cubes inside, a cabinet with drawers (prismatic joints, handle links) that may hold a
cube, and a microwave with a revolute door. Segmentation ids are PyBullet's ``body + (link + 1) << 24``
and the labels map them to node ids. World frame: robot base at the origin, +x forward, +y left, z up;
the table top is z = 0.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, field

import numpy as np
from gsr.perception.frame import InstanceLabel
from gsr.perception.geometry import Instance
from gsr.perception.relations import RelationThresholds, descriptive_relations
from gsr.skills.urdf import Joint, Link, Shape, box, urdf_text

from gsr.scene_graph import Edge, Node, SceneGraph

COLORS_RGB: dict[str, tuple[float, float, float]] = {
    "red": (0.85, 0.1, 0.1),
    "green": (0.1, 0.7, 0.15),
    "blue": (0.1, 0.25, 0.85),
    "yellow": (0.95, 0.85, 0.1),
    "purple": (0.55, 0.15, 0.7),
    "orange": (0.95, 0.5, 0.05),
    "cyan": (0.1, 0.8, 0.85),
    "pink": (0.95, 0.45, 0.7),
}
TABLE_COLOR = (0.62, 0.5, 0.38)
LEVELS = ("low", "middle", "high")


@dataclass
class Placed:
    """One placed thing: its exact upright box (centre, half extents, yaw) and scene-graph facts."""

    node: str
    category: str
    center: np.ndarray
    half: np.ndarray
    yaw: float = 0.0
    color: str | None = None
    parent: str | None = None
    states: tuple[str, ...] = ()
    support: tuple[str, str] | None = None  # (relation, target)
    floor: float | None = None  # containers: height of the inner floor's top (m)


@dataclass
class Scene:
    """A built PyBullet scene: its client, labels by segmentation id, and the ground truth."""

    client: int
    labels: dict[int, InstanceLabel] = field(default_factory=dict)
    placed: list[Placed] = field(default_factory=list)
    joints: dict[str, float] = field(default_factory=dict)  # part node -> joint position

    def truth(self, descriptive: bool = True) -> SceneGraph:
        """The exact ground-truth graph: nodes, support edges, part states and openings.

        With ``descriptive``, ``adjacent`` and the robot-frame directions come from the same rules
        perception applies (gsr.perception.relations), evaluated on the exact boxes instead of points.
        """
        nodes = []
        for p in self.placed:
            attrs: dict[str, str | float] = {"color": p.color} if p.color else {}
            if p.node in self.joints:
                key = "open_distance" if p.category == "drawer" else "open_angle"
                attrs[key] = round(self.joints[p.node], 4)
            nodes.append(
                Node(id=p.node, category=p.category, attributes=attrs, states=p.states, parent=p.parent)
            )
        support = {p.node: p.support for p in self.placed if p.support}
        edges = {(a, rel, b) for a, (rel, b) in support.items()}
        if descriptive:
            edges |= set(
                descriptive_relations(
                    [_exact_instance(p) for p in self.placed], support, RelationThresholds()
                )
            )
        return SceneGraph(
            nodes=tuple(nodes),
            edges=tuple(Edge(source=a, relation=r, target=b) for a, r, b in sorted(edges)),
            metadata={"source": "perception_scenes"},
        )

    def close(self) -> None:
        """Disconnect the PyBullet client."""
        import pybullet as pb

        pb.disconnect(self.client)


def _exact_instance(p: Placed) -> Instance:
    """An Instance carrying the exact box of a placed thing (its 8 corners as points)."""
    label = InstanceLabel(id=p.node, category=p.category, color=p.color, parent=p.parent)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * p.half
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    pts = corners @ rot.T + p.center
    inst = Instance(p.node, label, pts, np.zeros((8, 3), np.uint8))
    inst.center, inst.size, inst.yaw = p.center.copy(), 2.0 * p.half, p.yaw
    inst.aabb_min, inst.aabb_max = pts.min(axis=0), pts.max(axis=0)
    return inst


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


#: One box of a body: half extents, offset in the link frame, colour (RGB).
Box = tuple[np.ndarray, np.ndarray, tuple[float, float, float]]


def _shapes(boxes: list[Box]) -> tuple[Shape, ...]:
    """The boxes as the URDF writer's visual-only shapes (no collision: nothing here is simulated)."""
    return tuple(
        box(tuple(map(float, o)), tuple(2.0 * float(x) for x in h), (*map(float, c), 1.0), collide=False)  # type: ignore[arg-type]
        for h, o, c in boxes
    )


def load_body(client: int, links: list[Link], position, yaw: float) -> tuple[int, dict[str, int]]:
    """Load ``links`` (the first is the base) as one fixed body through the skills URDF writer.

    Returns the body id and each link's PyBullet link index by name (the base is -1). The URDF text
    goes to a scratch file that is removed once PyBullet has read it, so building scenes leaves no files.
    """
    import pybullet as pb

    fd, path = tempfile.mkstemp(suffix=".urdf", prefix="gsr-scene-")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(urdf_text("scene_body", links))
        body = pb.loadURDF(
            path,
            list(map(float, position)),
            _quat(yaw),
            useFixedBase=True,
            physicsClientId=client,
        )
    finally:
        os.unlink(path)
    index = {links[0].name: -1}
    for j in range(pb.getNumJoints(body, physicsClientId=client)):
        index[pb.getJointInfo(body, j, physicsClientId=client)[12].decode()] = j
    return body, index


class SceneBuilder:
    """Adds primitive objects to a DIRECT PyBullet client and records their labels and truth.

    The bodies are written by the skills layer's URDF writer (``gsr.skills.urdf``, through
    :func:`load_body`); what is the builder's own is the exact placement, the labels and the truth.
    """

    def __init__(self, rng: np.random.Generator) -> None:
        import pybullet as pb

        self.pb = pb
        self.rng = rng
        self.scene = Scene(client=pb.connect(pb.DIRECT))
        self._counts: dict[str, int] = {}
        self._footprints: list[tuple[np.ndarray, float]] = []  # (xy, radius) on the table

    def name(self, stem: str) -> str:
        """A fresh node id ``stem_k``."""
        self._counts[stem] = self._counts.get(stem, 0) + 1
        return f"{stem}_{self._counts[stem]}"

    def _body(
        self, boxes: list[Box], pos, yaw: float, links: tuple[Link, ...] = ()
    ) -> tuple[int, dict[str, int]]:
        """A fixed body whose base is a compound of boxes, with optional jointed ``links`` on it."""
        return load_body(self.scene.client, [Link("base", _shapes(boxes), 0.0), *links], pos, yaw)

    def _label(self, body: int, link: int, label: InstanceLabel) -> None:
        self.scene.labels[body + ((link + 1) << 24)] = label

    def table(self) -> None:
        """The table: top at z = 0, 1.2 m deep (x 0..1.2), 1.6 m wide."""
        half = np.array([0.6, 0.8, 0.025])
        body, _ = self._body([(half, np.zeros(3), TABLE_COLOR)], (0.6, 0.0, -0.025), 0.0)
        self._label(body, -1, InstanceLabel(id="table", category="table"))
        self.scene.placed.append(Placed("table", "table", np.array([0.6, 0.0, -0.025]), half))

    def free_spot(self, radius: float, x=(0.35, 0.8), y=(-0.45, 0.45)) -> np.ndarray | None:
        """A table position whose disc of ``radius`` overlaps nothing placed yet (rejection sampling)."""
        for _ in range(200):
            p = np.array([self.rng.uniform(*x), self.rng.uniform(*y)])
            if all(np.linalg.norm(p - q) > radius + r + 0.02 for q, r in self._footprints):
                self._footprints.append((p, radius))
                return p
        return None

    def box_object(
        self,
        category: str,
        color: str,
        half: np.ndarray,
        xy: np.ndarray,
        z_bottom: float,
        yaw: float,
        support: tuple[str, str],
    ) -> Placed:
        """A solid box-shaped object (cube, block, plate-like slab) resting at ``z_bottom``."""
        node = self.name(f"{color}_{category}")
        center = np.array([xy[0], xy[1], z_bottom + half[2]])
        body, _ = self._body([(half, np.zeros(3), COLORS_RGB.get(color, (0.9, 0.9, 0.9)))], center, yaw)
        self._label(body, -1, InstanceLabel(id=node, category=category, color=color))
        placed = Placed(node, category, center, half, yaw, color, support=support)
        self.scene.placed.append(placed)
        return placed

    def open_box(self, color: str, xy: np.ndarray, yaw: float) -> Placed:
        """An open-top box (floor and four walls), a container on the table."""
        hx, hy, hz, t = self.rng.uniform(0.07, 0.1), self.rng.uniform(0.07, 0.1), 0.04, 0.006
        rgb = COLORS_RGB[color]
        parts = [
            (np.array([hx, hy, t / 2]), np.array([0, 0, -hz + t / 2]), rgb),
            (np.array([t / 2, hy, hz]), np.array([hx - t / 2, 0, 0]), rgb),
            (np.array([t / 2, hy, hz]), np.array([-hx + t / 2, 0, 0]), rgb),
            (np.array([hx, t / 2, hz]), np.array([0, hy - t / 2, 0]), rgb),
            (np.array([hx, t / 2, hz]), np.array([0, -hy + t / 2, 0]), rgb),
        ]
        node = self.name(f"{color}_box")
        center = np.array([xy[0], xy[1], hz])
        body, _ = self._body(parts, center, yaw)
        self._label(body, -1, InstanceLabel(id=node, category="box", color=color))
        placed = Placed(node, "box", center, np.array([hx, hy, hz]), yaw, color, support=("on", "table"))
        placed.floor = float(center[2] - hz + t)
        self.scene.placed.append(placed)
        return placed

    def cabinet(self, xy: np.ndarray, yaw: float, levels: int, openings: list[float]) -> list[Placed]:
        """A cabinet facing the robot with ``levels`` drawers (prismatic) and a handle link on each."""
        pb, cid = self.pb, self.scene.client
        hw, hd, dh, t = 0.2, 0.15, 0.06, 0.01  # half width (y), half depth (x), half drawer height, wall
        hh = levels * dh + t
        wood = (0.75, 0.75, 0.72)
        shell = [
            (np.array([hd, hw, t / 2]), np.array([0, 0, hh - t / 2]), wood),  # top
            (np.array([hd, hw, t / 2]), np.array([0, 0, -hh + t / 2]), wood),  # bottom
            (np.array([hd, t / 2, hh]), np.array([0, hw - t / 2, 0]), wood),  # sides
            (np.array([hd, t / 2, hh]), np.array([0, -hw + t / 2, 0]), wood),
            (np.array([t / 2, hw, hh]), np.array([hd - t / 2, 0, 0]), wood),  # back
        ]
        dcol = (0.55, 0.4, 0.3)
        dw, dd, dz = hw - t - 0.004, hd - t, dh - 0.006  # drawer half extents inside the shell
        drawer = [
            (np.array([t / 2, dw, dz]), np.array([-dd + t / 2, 0, 0]), dcol),  # front panel
            (np.array([dd, dw, t / 2]), np.array([0, 0, -dz + t / 2]), dcol),  # floor
            (np.array([dd, t / 2, dz * 0.6]), np.array([0, dw - t / 2, -dz * 0.4]), dcol),  # sides
            (np.array([dd, t / 2, dz * 0.6]), np.array([0, -dw + t / 2, -dz * 0.4]), dcol),
            (np.array([t / 2, dw, dz * 0.6]), np.array([dd - t / 2, 0, -dz * 0.4]), dcol),  # back
        ]
        hx = 0.01  # the handle's half depth
        handle = [(np.array([hx, 0.05, 0.008]), np.zeros(3), (0.2, 0.2, 0.2))]
        n = levels
        heights = [-hh + t + dh * (2 * i + 1) for i in range(n)]
        links: list[Link] = []
        for i in range(n):  # drawer i slides out along -x; its front is flush with the shell when closed
            slide = Joint("prismatic", (-t, 0.0, heights[i]), (-1.0, 0.0, 0.0), 0.0, 2 * hd)
            pull = Joint("fixed", (-dd - hx, 0.0, 0.0), (0.0, 0.0, 1.0))
            links += [
                Link(f"drawer_{i}", _shapes(drawer), 0.0, "base", slide),
                Link(f"handle_{i}", _shapes(handle), 0.0, f"drawer_{i}", pull),
            ]
        node = self.name("cabinet")
        center = np.array([xy[0], xy[1], hh])
        body, index = self._body(shell, center, yaw, tuple(links))
        self._label(body, -1, InstanceLabel(id=node, category="cabinet"))
        out = [Placed(node, "cabinet", center, np.array([hd, hw, hh]), yaw, support=("on", "table"))]
        names = LEVELS if n == 3 else (("low", "high") if n == 2 else ("low",))
        for i in range(n):
            drawer_link, handle_link = index[f"drawer_{i}"], index[f"handle_{i}"]
            pb.resetJointState(body, drawer_link, openings[i], physicsClientId=cid)
            part = f"{node}/drawer_{names[i]}"
            self._label(body, drawer_link, InstanceLabel(id=part, category="drawer", parent=node))
            self._label(body, handle_link, InstanceLabel(keypoint_of=part, name="handle"))
            c, s = math.cos(yaw), math.sin(yaw)
            off = np.array([-openings[i] - t, 0.0])
            dc = center + np.array([c * off[0] - s * off[1], s * off[0] + c * off[1], heights[i]])
            # open = past half the travel, the travel being 80% of the depth (as the skills assets)
            state = ("open",) if openings[i] > 0.4 * 2 * hd else ("closed",)
            placed = Placed(part, "drawer", dc, np.array([dd, dw, dz]), yaw, parent=node, states=state)
            placed.floor = float(dc[2] - dz + t)
            out.append(placed)
            self.scene.joints[part] = openings[i]
        self.scene.placed.extend(out)
        return out

    def microwave(self, xy: np.ndarray, yaw: float, angle: float) -> None:
        """A microwave (open-front shell) with a door hinged on its left edge, opened by ``angle`` rad."""
        pb = self.pb
        hd, hw, hh, t = 0.14, 0.2, 0.12, 0.01
        grey = (0.3, 0.3, 0.32)
        shell = [
            (np.array([hd, hw, t / 2]), np.array([0, 0, hh - t / 2]), grey),
            (np.array([hd, hw, t / 2]), np.array([0, 0, -hh + t / 2]), grey),
            (np.array([hd, t / 2, hh]), np.array([0, hw - t / 2, 0]), grey),
            (np.array([hd, t / 2, hh]), np.array([0, -hw + t / 2, 0]), grey),
            (np.array([t / 2, hw, hh]), np.array([hd - t / 2, 0, 0]), grey),
        ]
        door = [(np.array([0.008, hw, hh]), np.array([-0.008, -hw, 0.0]), (0.1, 0.1, 0.12))]
        # hinged on the front-left edge (+y is left); a positive angle swings the free edge towards the robot
        hinge = Joint("revolute", (-hd, hw, 0.0), (0.0, 0.0, -1.0), 0.0, 1.6)
        node = self.name("microwave")
        center = np.array([xy[0], xy[1], hh])
        body, index = self._body(shell, center, yaw, (Link("door", _shapes(door), 0.0, "base", hinge),))
        pb.resetJointState(body, index["door"], angle, physicsClientId=self.scene.client)
        self._label(body, -1, InstanceLabel(id=node, category="microwave"))
        self._label(body, index["door"], InstanceLabel(id=f"{node}/door", category="door", parent=node))
        self.scene.placed.append(
            Placed(node, "microwave", center, np.array([hd, hw, hh]), yaw, support=("on", "table"))
        )
        state = ("open",) if angle > 0.8 else ("closed",)  # past half of a 1.6 rad travel
        self.scene.placed.append(
            Placed(f"{node}/door", "door", center, np.array([0.008, hw, hh]), yaw, parent=node, states=state)
        )
        self.scene.joints[f"{node}/door"] = angle


def random_scene(seed: int) -> Scene:
    """A random tabletop scene (deterministic per seed) with its ground truth."""
    rng = np.random.default_rng(seed)
    b = SceneBuilder(rng)
    b.table()
    palette = list(COLORS_RGB)
    fixtures_y = rng.permutation([-0.3, 0.3])
    if rng.random() < 0.7:  # a cabinet at the far edge, facing the robot
        levels = int(rng.integers(2, 4))
        openings = [float(rng.uniform(0.03, 0.2)) if rng.random() < 0.6 else 0.0 for _ in range(levels)]
        xy = np.array([rng.uniform(0.95, 1.0), fixtures_y[0] + rng.uniform(-0.05, 0.05)])
        b._footprints.append((xy, 0.28))
        parts = b.cabinet(xy, float(rng.uniform(-0.25, 0.25)), levels, openings)
        for drawer, opening in zip(parts[1:], openings, strict=True):
            if opening > 0.12 and rng.random() < 0.6:  # something in a well-opened drawer
                _cube_in(b, drawer, palette, rng, front_limit=opening)
    if rng.random() < 0.5:
        xy = np.array([rng.uniform(0.95, 1.0), fixtures_y[1] + rng.uniform(-0.05, 0.05)])
        b._footprints.append((xy, 0.28))
        angle = float(rng.uniform(0.2, 1.5)) if rng.random() < 0.7 else 0.0
        b.microwave(xy, float(rng.uniform(-0.25, 0.25)), angle)
    for _ in range(int(rng.integers(1, 3))):  # open boxes, some holding cubes
        xy = b.free_spot(0.14)
        if xy is None:
            continue
        box = b.open_box(str(rng.choice(palette)), xy, float(rng.uniform(0, math.pi)))
        for _ in range(int(rng.integers(0, 3))):
            _cube_in(b, box, palette, rng)
    for _ in range(int(rng.integers(0, 3))):  # plates with something on them
        xy = b.free_spot(0.11)
        if xy is None:
            continue
        half = np.array([0.09, 0.09, 0.008])
        plate = b.box_object(
            "plate", "yellow", half, xy, 0.0, float(rng.uniform(0, math.pi)), ("on", "table")
        )
        if rng.random() < 0.7:
            h = rng.uniform(0.02, 0.03)
            b.box_object(
                "cube",
                str(rng.choice(palette)),
                np.array([h, h, h]),
                xy + rng.uniform(-0.03, 0.03, 2),
                0.016,
                float(rng.uniform(0, math.pi)),
                ("on", plate.node),
            )
    for _ in range(int(rng.integers(2, 6))):  # loose cubes and block stacks
        xy = b.free_spot(0.05)
        if xy is None:
            continue
        h = rng.uniform(0.02, 0.03)
        cube = b.box_object(
            "cube",
            str(rng.choice(palette)),
            np.array([h, h, h]),
            xy,
            0.0,
            float(rng.uniform(0, math.pi)),
            ("on", "table"),
        )
        if rng.random() < 0.3:
            h2 = rng.uniform(0.018, h)
            b.box_object(
                "block",
                str(rng.choice(palette)),
                np.array([h2, h2, h2]),
                xy,
                2 * h,
                float(rng.uniform(0, math.pi)),
                ("on", cube.node),
            )
    return b.scene


def _cube_in(
    b: SceneBuilder, holder: Placed, palette: list, rng: np.random.Generator, front_limit=None
) -> None:
    """A cube resting on the floor of a box or drawer, inside its walls."""
    h = float(rng.uniform(0.018, 0.024))
    room = holder.half[:2] - h * 1.5 - 0.012
    if np.any(room <= 0):
        return
    local = rng.uniform(-room, room)
    if front_limit is not None:  # keep it in the part of the drawer that is pulled out
        local[0] = -holder.half[0] + h * 1.5 + 0.012 + rng.uniform(0, max(0.0, front_limit - 3 * h - 0.03))
    c, s = math.cos(holder.yaw), math.sin(holder.yaw)
    xy = holder.center[:2] + np.array([c * local[0] - s * local[1], s * local[0] + c * local[1]])
    assert holder.floor is not None, "only boxes and drawers hold cubes"
    z = holder.floor
    b.box_object(
        "cube", str(rng.choice(palette)), np.array([h, h, h]), xy, z, holder.yaw, ("in", holder.node)
    )
