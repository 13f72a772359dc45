"""Building a World from a TaskSpec or Layout: table, robot, procedural objects, parts and initial joints.

``build_world(task_or_layout, seed)`` is deterministic. Layout positions that overlap our asset sizes
are separated first (:func:`separate_footprints`); objects resting ``on`` another are set on its top
or into its interior; part nodes of the graph map to asset parts (:func:`resolve_part`).
"""

from __future__ import annotations

import numpy as np
from gsr.skills.asset_model import AssetModel
from gsr.skills.assets import asset_urdf_path, make_asset
from gsr.skills.box_slots import HAND_OVER_TOP, INSIDE_MARGIN, box_slots, turned_footprint
from gsr.skills.layout import layout_from_graph
from gsr.skills.packing import footprint
from gsr.skills.robot import Robot
from gsr.skills.shadow import SHADOW_DEPTH, SHADOW_SIDE, TALL, keep_reachable
from gsr.skills.sim_graph import graph_from_layout
from gsr.skills.world import JOINT_FRICTION, SETTLE_STEPS, SimObject, World

from gsr.categories import is_a
from gsr.errors import GSRError
from gsr.scene_graph import SceneGraph
from gsr.task_spec import Layout, PlacedObject, TaskSpec


def resolve_part(model: AssetModel, graph: SceneGraph, node_id: str) -> str:
    """The asset part a graph part node denotes (``wooden_cabinet_1/top_drawer`` -> ``drawer_2``); "" if none."""
    n = graph.node(node_id)
    name = node_id.split("/")[-1]
    cat = n.category
    if name in model.part_links:  # a part the asset has by that name (a microwave's top_side)
        return name
    if is_a(cat, "drawer"):
        drawers = sorted(p for p in model.articulations if p.startswith("drawer_"))
        level = n.attributes.get("level")
        if not isinstance(level, int):
            words = {
                "top": 2,
                "high": 2,
                "upper": 2,
                "middle": 1,
                "mid": 1,
                "bottom": 0,
                "low": 0,
                "lower": 0,
            }
            level = next((v for k, v in words.items() if k in name), 0)
        siblings = [m for m in graph.nodes if m.parent == n.parent and is_a(m.category, "drawer")]
        if len(siblings) < len(drawers) and isinstance(level, int):  # two-drawer cabinets: the lowest ones
            level = min(level, len(drawers) - 1)
        return drawers[min(max(level, 0), len(drawers) - 1)] if drawers else ""
    if is_a(cat, "cabinet_top"):
        return "top_side" if "top_side" in model.part_links else ""
    if is_a(cat, "compartment"):
        # by the side its name gives (``back_compartment`` -> ``compartment_back``), else the front one
        compartments = [k for k in model.interiors if k.startswith("compartment_")]
        words = set(name.replace("-", "_").split("_"))
        named = [k for k in compartments if k.removeprefix("compartment_") in words]
        fallback = "compartment_front" if "compartment_front" in compartments else ""
        return named[0] if named else fallback
    if is_a(cat, "door"):
        return model.open_part or ""
    if is_a(cat, "button") or is_a(cat, "switch"):
        return model.switch_part or ""
    if is_a(cat, "burner"):
        return "burner" if "burner" in model.part_links else ""
    return ""


def _table_id(graph: SceneGraph) -> str:
    """The node the table body stands for: the graph's table, else its floor (LIBERO object scenes)."""
    for surface in ("table", "floor"):
        for n in graph.nodes:
            if n.parent is None and is_a(n.category, surface):
                return n.id
    return "table"


def _rest_order(layout: Layout) -> list[PlacedObject]:
    ids = {o.id for o in layout.objects}
    done: set[str] = set()
    out: list[PlacedObject] = []
    pending = list(layout.objects)
    while pending:
        progressed = False
        for o in list(pending):
            host = (o.on or "").split("/")[0]
            if host in ids and host not in done:
                continue
            out.append(o)
            done.add(o.id)
            pending.remove(o)
            progressed = True
        if not progressed:
            raise GSRError(f"layout: support cycle among {', '.join(o.id for o in pending)}")
    return out


def build_world(
    task_or_layout: TaskSpec | Layout,
    seed: int = 0,
    graph: SceneGraph | None = None,
    debug_weld: bool = False,
) -> World:
    """Build the simulated world for a task (or a bare layout plus its graph), deterministic per seed.

    A task without a layout gets one from :func:`gsr.skills.layout.layout_from_graph`. ``debug_weld``
    welds a grasped object to the hand with a fixed constraint (debugging only: it hides grasp slips; off
    by default and never used by benchmarks or the executor).
    """
    import pybullet as p

    if isinstance(task_or_layout, TaskSpec):
        graph = task_or_layout.initial
        layout = task_or_layout.layout or layout_from_graph(graph, seed)
    else:
        layout = task_or_layout
        graph = graph or graph_from_layout(layout)
    client = p.connect(p.DIRECT)
    try:
        return _populate(client, layout, graph, seed, debug_weld)
    except Exception:
        p.disconnect(client)
        raise


def _populate(client: int, layout: Layout, graph: SceneGraph, seed: int, debug_weld: bool) -> World:
    import pybullet as p

    p.resetSimulation(physicsClientId=client)
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    p.setPhysicsEngineParameter(fixedTimeStep=1 / 240, numSolverIterations=80, physicsClientId=client)
    th = layout.table_height
    table_model = make_asset("table", (layout.table_size[0], layout.table_size[1], 0.05))
    table_body = p.loadURDF(
        str(asset_urdf_path(table_model)), (0, 0, th), useFixedBase=True, physicsClientId=client
    )
    p.changeDynamics(table_body, -1, lateralFriction=0.8, physicsClientId=client)
    # the base's rails run beside the table's near edge (x) and along it (y)
    edge = -layout.table_size[0] / 2
    half_y = layout.table_size[1] / 2
    # (0.9 m back: a cabinet at the desk's front edge opens its drawers 30 cm past it, handle included)
    robot = Robot.load(client, th, (edge - 0.9, edge + 0.05), (-half_y, half_y))
    # the base is clamped to the table's edge: its carriage and link0 slide over the edge, not on it
    for link in (-1, *robot.base):
        p.setCollisionFilterPair(robot.body, table_body, link, -1, 0, physicsClientId=client)
    start_y = float(np.clip(np.mean([o.position[1] for o in layout.objects] or [0.0]), -half_y, half_y))
    robot.reset((edge - 0.1, start_y, *robot.q()[2:]))
    world = World(client, robot, table_body, _table_id(graph), graph, layout, seed, debug_weld=debug_weld)
    world.regions = {r.name: r for r in layout.regions}
    for r in layout.regions:
        # a region node is named by the region's name, its part name after the slash, or LIBERO's name
        for n in graph.nodes:
            if n.id.endswith("/" + r.name) or n.attributes.get("libero_region") == r.name:
                world.regions[n.id] = r
    rng = np.random.default_rng(seed)
    occupied: dict[str, int] = {}
    world.adjusted, lid_yaws = separate_with_lids(layout)
    for placed in _rest_order(layout):
        shift = world.adjusted.get(placed.id)
        if shift is not None:
            x, y, z = placed.position
            placed = placed.model_copy(update={"position": (x + shift[0], y + shift[1], z)})
        if placed.id in lid_yaws:
            # the side separate_with_lids kept free
            placed = placed.model_copy(update={"yaw": lid_yaws[placed.id]})
        _load(world, placed, rng, occupied)
    for n in graph.nodes:
        if n.parent in world.objects:
            part = resolve_part(world.objects[n.parent].model, graph, n.id)
            world.parts[n.id] = (n.parent, part)
    _initial_joints(world, layout)
    _clear_start(world)
    # an object behind a tall fixture that no pick reaches moves to the nearest spot one does
    for oid, (dx, dy) in keep_reachable(world).items():
        x0, y0 = world.adjusted.get(oid, (0.0, 0.0))
        world.adjusted[oid] = (round(x0 + dx, 4), round(y0 + dy, 4))
    for _ in range(SETTLE_STEPS):
        world.robot.hold(world.robot.q())
        world.step()
    return world


def _clear_start(world: World, margin: float = 0.02) -> None:
    """Back the robot's base off along its x rail until base and shoulder clear every object.

    An open drawer of a cabinet near the table's front edge reaches over the rails; a base started
    inside it would push the drawer shut before the first step (the task's graph says it is open).
    """
    import pybullet as p

    r = world.robot
    q = r.q()
    for x in np.arange(q[0], r.lower[0] - 1e-9, -0.05):
        q[0] = x
        r.reset(q)
        hits = any(
            p.getClosestPoints(r.body, o.body, margin, linkIndexA=link, physicsClientId=world.client)
            for o in world.objects.values()
            for link in (*r.base, r.arm[0], r.arm[1])
        )
        if not hits:
            return


#: Objects a layout puts in a drawer start in its front part: the first row's centre this far from the
#: front wall, the second row behind it (m).
DRAWER_SLOT_X, DRAWER_ROW_PITCH = 0.065, 0.05
#: Room kept between a tall fixture and a movable object (m): a hand's width.
HAND_CLEARANCE = 0.06
#: How much farther (m) a lidded box may be pushed to keep it out of a tall fixture's shadow.
LID_EXTRA_PUSH = 0.25
#: Footprints whose circumscribed radius is larger than this (m) are separated as rectangles.
LARGE_FOOTPRINT = 0.08


def rect_overlap(
    d: np.ndarray, a: tuple[np.ndarray, float], b: tuple[np.ndarray, float], margin: float
) -> tuple[np.ndarray, float] | None:
    """The shortest push (unit direction from a to b, length) separating two oriented rectangles by
    ``margin``; None when they are that far apart already (separating-axis test)."""
    axes = []
    for _, yaw in (a, b):
        c, s = np.cos(yaw), np.sin(yaw)
        axes += [np.array([c, s]), np.array([-s, c])]

    def radius(r: tuple[np.ndarray, float], n: np.ndarray) -> float:
        (hx, hy), yaw = r
        c, s = np.cos(yaw), np.sin(yaw)
        return float(hx * abs(c * n[0] + s * n[1]) + hy * abs(-s * n[0] + c * n[1]))

    best: tuple[np.ndarray, float] | None = None
    for n in axes:
        along = float(np.dot(d, n))
        overlap = radius(a, n) + radius(b, n) + margin - abs(along)
        if overlap <= 0:
            return None
        if best is None or overlap < best[1]:
            best = (n * (1.0 if along >= 0 else -1.0), overlap + 1e-4)
    return best


def drawer_sweep(model: AssetModel) -> float:
    """How far in front of an asset (local -x) its drawers reach when open, with their pull bars and
    room for the hand on them (m); 0 without drawers."""
    travel = [abs(a.open - a.closed) for a in model.articulations.values() if a.kind == "drawer"]
    return max(travel) + 0.06 if travel else 0.0


def separate_footprints(
    layout: Layout, margin: float = 0.008, rounds: int = 60
) -> dict[str, tuple[float, float]]:
    """Shifts that keep table-standing objects from overlapping (a layout may not know our asset sizes).

    Circles of each object's footprint are pushed apart (movable ones only; fixtures stay) until no two
    overlap; deterministic. Returns id -> (dx, dy) for the objects that moved. An open lid's room is
    kept free too, on the side :func:`lid_sides` chooses.
    """
    return separate_with_lids(layout, margin, rounds)[0]


def separate_with_lids(
    layout: Layout, margin: float = 0.008, rounds: int = 60
) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
    """The separation's shifts and each lidded box's yaw (the side its lid opens to), decided together.

    A sliding lid opens over the side :func:`lid_side_yaw` prefers and the separation keeps that room,
    with a hand's width round it, free. Where keeping it pushes the box into a tall fixture's shadow
    (behind it from the robot's side, :func:`in_shadow`), the pushes the table's edges stop are sent to
    the box's other side along that edge, then the other lid side is tried (both ways): the first choice
    that leaves the box out of the shadow, pushed at most :data:`LID_EXTRA_PUSH` farther than the
    preferred one, wins; the preferred one when none does. (A box the layout puts into a fixture's
    footprint is pushed out; a push the table's back edge stops is deflected sideways, before by the
    sign of a millimetre's offset between the two centres.)
    """
    boxes = [
        o
        for o in layout.objects
        if o.on is None and not o.fixed and _sliding_lid(make_asset(o.asset, o.size)) is not None
    ]
    preferred = {o.id: lid_side_yaw(layout, o) for o in boxes}
    first = _separate(layout, margin, rounds, preferred, {})
    fixtures = [o for o in layout.objects if o.on is None and (o.fixed or make_asset(o.asset, o.size).fixed)]

    def shadowed(shifts: dict[str, tuple[float, float]]) -> set[str]:
        return {o.id for o in boxes if o.id in shifts and in_shadow(layout, o, shifts[o.id], fixtures)}

    if not shadowed(first):
        return first, preferred
    flipped = {
        k: (float(np.arctan2(np.sin(v + np.pi), np.cos(v + np.pi))) if k in shadowed(first) else v)
        for k, v in preferred.items()
    }

    def pushed(shifts: dict[str, tuple[float, float]]) -> float:
        return max(float(np.hypot(*shifts.get(o.id, (0.0, 0.0)))) for o in boxes)

    hidden = shadowed(first)
    for sides in (preferred, flipped):
        for sign in (0.0, 1.0, -1.0):
            if sides is preferred and not sign:
                continue  # that is the first separation
            shifts = _separate(layout, margin, rounds, sides, {k: sign for k in hidden if sign})
            if not shadowed(shifts) and pushed(shifts) <= pushed(first) + LID_EXTRA_PUSH:
                return shifts, sides
    return first, preferred


def in_shadow(
    layout: Layout, placed: PlacedObject, shift: tuple[float, float], fixtures: list[PlacedObject]
) -> bool:
    """Whether ``placed`` (moved by ``shift``) stands behind a tall fixture seen from the robot's side
    (world -x), as :mod:`gsr.skills.shadow` counts it: within its depth behind the fixture's back face
    and its side room beside it; the layout's rectangles, no simulation."""
    c = np.array(placed.position[:2], dtype=float) + np.array(shift)
    for f in fixtures:
        m = make_asset(f.asset, f.size)
        if m.extent[2] < TALL:
            continue
        cs, sn = abs(np.cos(f.yaw)), abs(np.sin(f.yaw))
        hx = (m.extent[0] * cs + m.extent[1] * sn) / 2
        hy = (m.extent[0] * sn + m.extent[1] * cs) / 2
        fx, fy = f.position[0], f.position[1]
        if (
            fx + hx - 0.02 < c[0] < fx + hx + SHADOW_DEPTH
            and fy - hy - SHADOW_SIDE < c[1] < fy + hy + SHADOW_SIDE
        ):
            return True
    return False


def _separate(
    layout: Layout,
    margin: float,
    rounds: int,
    sides: dict[str, float],
    deflect: dict[str, float],
) -> dict[str, tuple[float, float]]:
    """The separation itself: ``sides`` the lidded boxes' yaws, ``deflect`` the side (+1 / -1 along the
    other axis) a push an edge of the table stops goes to for the objects named (else away from the
    object pushing)."""
    items = [o for o in layout.objects if o.on is None]
    pos = {o.id: np.array(o.position[:2], dtype=float) for o in items}
    # circumscribed circles: a rotated box reaches its half-diagonal
    rad = {o.id: float(np.hypot(*make_asset(o.asset, o.size).extent[:2]) / 2) for o in items}
    rect = {o.id: (np.array(make_asset(o.asset, o.size).extent[:2]) / 2, o.yaw) for o in items}
    # a cabinet's footprint reaches as far as its drawers open (and their pull bars and the hand on
    # them): what stands there would be under an open drawer, out of the hand's reach, or swept away
    off = {o.id: np.zeros(2) for o in items}
    for o in items:
        sweep = drawer_sweep(make_asset(o.asset, o.size))
        if sweep > 0:
            half_xy, yaw = rect[o.id]
            rect[o.id] = (half_xy + np.array([sweep / 2, 0.0]), yaw)
            off[o.id] = -sweep / 2 * np.array([np.cos(yaw), np.sin(yaw)])
    # a lidded box's open lid lies at rim height over the side lid_side_yaw chooses: what stood there
    # would be under it (no hand reaches it), a fixture there would stop the lid short over the box
    lids: dict[str, tuple[np.ndarray, tuple[np.ndarray, float]]] = {}
    for o in items:
        travel = _sliding_lid(make_asset(o.asset, o.size))
        if travel is not None and o.id in sides:
            c, s = np.cos(sides[o.id]), np.sin(sides[o.id])
            lids[o.id] = (np.array([[c, -s], [s, c]]) @ travel, rect[o.id])
    fixed = {o.id for o in items if o.fixed or make_asset(o.asset, o.size).fixed}
    tall = {o.id for o in items if o.id in fixed and make_asset(o.asset, o.size).extent[2] > 0.15}
    # a push keeps an object on the table (an object the layout puts nearer an edge may stay there):
    # what a push along x cannot take goes sideways along y, and the other way round
    half = np.array(layout.table_size[:2], dtype=float) / 2
    bound = {
        o.id: np.maximum(half - max(make_asset(o.asset, o.size).extent[:2]) / 2 - 0.01, np.abs(pos[o.id]))
        for o in items
    }

    # named regions where nothing starts (LIBERO's stove-front region) are destinations: an object
    # pushed into one would start "on" it, unlike its graph says
    starts = [np.array(o.position[:2], dtype=float) for o in layout.objects]
    empty = [
        r.bounds
        for r in layout.regions
        if not any(r.bounds[0] <= c[0] <= r.bounds[2] and r.bounds[1] <= c[1] <= r.bounds[3] for c in starts)
    ]

    def keep_out(start: np.ndarray, new: np.ndarray) -> np.ndarray:
        for x0, y0, x1, y1 in empty:
            if x0 <= new[0] <= x1 and y0 <= new[1] <= y1:
                # stop at the edge it came in by (the smaller correction if it came in at a corner)
                fixes = []
                for axis, lo, hi in ((0, x0, x1), (1, y0, y1)):
                    if start[axis] < lo:
                        fixes.append((new[axis] - lo + 1e-3, axis, lo - 1e-3))
                    elif start[axis] > hi:
                        fixes.append((hi - new[axis] + 1e-3, axis, hi + 1e-3))
                if fixes:
                    _, axis, value = min(fixes)
                    new = new.copy()
                    new[axis] = value
        return new

    def push(oid: str, vec: np.ndarray, away: np.ndarray) -> None:
        # ``away``: from the other object's centre to this one's (the side a deflected push goes to)
        new = pos[oid] + vec
        clipped = np.clip(new, -bound[oid], bound[oid])
        left = np.abs(new - clipped)
        for axis in (0, 1):
            other = 1 - axis
            if left[axis] > 1e-9:
                sign = deflect.get(oid) or (1.0 if away[other] > 0 else -1.0)
                clipped[other] = np.clip(
                    clipped[other] + sign * left[axis], -bound[oid][other], bound[oid][other]
                )
        pos[oid] = keep_out(pos[oid], clipped)

    def clash(a: str, b: str, pa: np.ndarray, pb: np.ndarray) -> tuple[np.ndarray, float] | None:
        """The push separating ``b`` at ``pb`` from ``a`` at ``pa`` (unit direction a -> b, length), or None."""
        d = pb - pa
        pushes = [
            # beside the open lid the hand needs its width, as beside a tall fixture
            rect_overlap(pb + lid_b[0] - pa - off[a], rect[a], lid_b[1], HAND_CLEARANCE)
            for lid_b in [lids.get(b)]
            if lid_b is not None
        ] + [
            rect_overlap(pb + off[b] - pa - lid_a[0], lid_a[1], rect[b], HAND_CLEARANCE)
            for lid_a in [lids.get(a)]
            if lid_a is not None
        ]
        base = _footprint_clash(a, b, d)
        found = [q for q in (*pushes, base) if q is not None]
        return max(found, key=lambda q: q[1]) if found else None

    def _footprint_clash(a: str, b: str, d: np.ndarray) -> tuple[np.ndarray, float] | None:
        if max(rad[a], rad[b]) > LARGE_FOOTPRINT:
            d = d + off[b] - off[a]
            # beside a tall fixture (a cabinet) the hand needs its own width to grasp
            gap = HAND_CLEARANCE if {a, b} & tall else margin
            # a box or cabinet: its rectangle, not its circumscribed circle (which would push
            # neighbours off a 60 cm deep desk)
            return rect_overlap(d, rect[a], rect[b], gap)
        dist = float(np.linalg.norm(d))
        need = rad[a] + rad[b] + margin
        if dist >= need:
            return None
        return (d / dist if dist > 1e-9 else np.array([0.0, 1.0])), need - dist + 1e-4

    for _ in range(rounds):
        moved = False
        for i, a in enumerate(items):
            for b in items[i + 1 :]:
                if a.id in fixed and b.id in fixed:
                    continue
                sep = clash(a.id, b.id, pos[a.id], pos[b.id])
                if sep is None:
                    continue
                u, amount = sep
                d = pos[b.id] - pos[a.id]
                if a.id in fixed:
                    push(b.id, u * amount, d)
                elif b.id in fixed:
                    push(a.id, -u * amount, -d)
                else:
                    push(a.id, -u * amount / 2, -d)
                    push(b.id, u * amount / 2, d)
                moved = True
        if not moved:
            break
    # pushes that met the desk's edges from both sides (two mugs in a corner) leave overlaps: such an
    # object moves to the nearest free spot on the desk instead
    for o in items:
        if o.id in fixed or all(
            clash(o.id, q.id, pos[o.id], pos[q.id]) is None for q in items if q.id != o.id
        ):
            continue
        spots = [
            np.array([x, y])
            for x in np.arange(-bound[o.id][0], bound[o.id][0] + 1e-9, 0.02)
            for y in np.arange(-bound[o.id][1], bound[o.id][1] + 1e-9, 0.02)
            if not any(x0 <= x <= x1 and y0 <= y <= y1 for x0, y0, x1, y1 in empty)
        ]
        spots.sort(key=lambda c: float(np.linalg.norm(c - pos[o.id])))
        for c in spots:
            if all(clash(o.id, q.id, c, pos[q.id]) is None for q in items if q.id != o.id):
                pos[o.id] = c
                break
    return {
        o.id: (round(float(pos[o.id][0] - o.position[0]), 4), round(float(pos[o.id][1] - o.position[1]), 4))
        for o in items
        if np.linalg.norm(pos[o.id] - np.array(o.position[:2])) > 1e-4
    }


def _sliding_lid(model: AssetModel) -> np.ndarray | None:
    """The way a sliding lid moves from closed to open in the asset's frame (x, y; its length is the
    travel), or None for an asset without one."""
    lid = next((a for a in model.articulations.values() if a.kind == "lid"), None)
    link = next((lk for lk in model.links if lid is not None and lk.name == lid.link), None)
    if lid is None or link is None or link.joint is None or link.joint.type != "prismatic":
        return None
    return np.array(link.joint.axis[:2], dtype=float) * (lid.open - lid.closed)


def lid_side_yaw(layout: Layout, placed: PlacedObject) -> float:
    """The layout's yaw or its half turn, whichever leaves the room a sliding lid opens into clearest.

    A box's rectangle is the same either way round; only the end its lid slides off differs. The open
    lid stays at rim height beside the box, and a hand reaching for anything under or next to it is
    blocked, so the lid opens over the emptiest side (a fixture in its way counts as much as the table's
    near edge, where the robot's base slides), preferring the side away from the robot (-x). Decided on
    the layout's own positions: :func:`separate_footprints` then keeps that side free.
    """
    model = make_asset(placed.asset, placed.size)
    ax = _sliding_lid(model)
    if ax is None or placed.on or placed.fixed or model.fixed:
        return placed.yaw
    half = np.array(model.extent[:2], dtype=float) / 2
    others, fixtures = [], []
    for o in layout.objects:
        if o.id == placed.id or o.on:
            continue
        m = make_asset(o.asset, o.size)
        if o.fixed or m.fixed:
            fixtures.append((np.array(o.position[:2], dtype=float), o.yaw, np.array(m.extent[:2]) / 2))
        else:
            others.append(np.array(o.position[:2], dtype=float))
    centre = np.array(placed.position[:2], dtype=float)
    # the robot's base slides over the table's near edge; a lid reaching 0.2 m past that edge was pushed
    # shut by it in GSR-Bench runs, one reaching 0.16 m past it was not
    edge = -layout.table_size[0] / 2 - 0.18

    def cost(yaw: float) -> float:
        c, s = np.cos(yaw), np.sin(yaw)
        rot = np.array([[c, -s], [s, c]])
        lid_centre = centre + rot @ ax
        total = 0.0
        for q in others:
            local = rot.T @ (q - lid_centre)
            gap = float(np.linalg.norm(np.maximum(np.abs(local) - half, 0.0)))
            total += max(0.0, 0.12 - gap)  # within a hand's reach of the lid's edge (or under it)
        for f, fyaw, fhalf in fixtures:
            # a lid running into a fixture stops short and still covers part of the box
            if rect_overlap(f - lid_centre, (half, yaw), (fhalf, fyaw), 0.0) is not None:
                total += 1.0
        # far past the table's near edge the lid hangs where the robot's base slides and gets pushed shut
        corners = [lid_centre + rot @ (half * (i, j)) for i in (-1, 1) for j in (-1, 1)]
        if min(float(c[0]) for c in corners) < edge:
            total += 1.0
        return total - 0.01 * float(lid_centre[0])  # tie-break: away from the robot's side

    best = min((placed.yaw, placed.yaw + np.pi), key=cost)
    return float(np.arctan2(np.sin(best), np.cos(best)))


def _load(world: World, placed: PlacedObject, rng: np.random.Generator, occupied: dict[str, int]) -> None:
    import pybullet as p

    node = world.graph.node(placed.id) if world.graph.has_node(placed.id) else None
    color = placed.color or (node.color if node else None)
    model = make_asset(placed.asset, placed.size, color)
    fixed = placed.fixed or model.fixed
    x, y, z = placed.position
    th = world.layout.table_height
    yaw = placed.yaw
    if placed.on:
        x, y, z = _rest_on(world, placed, model, occupied)
    else:
        z = max(z, th) + 0.002
    quat = p.getQuaternionFromEuler((0, 0, yaw))
    body = p.loadURDF(
        str(asset_urdf_path(model)), (x, y, z), quat, useFixedBase=fixed, physicsClientId=world.client
    )
    links = {model.links[0].name: -1}
    for j in range(p.getNumJoints(body, physicsClientId=world.client)):
        info = p.getJointInfo(body, j, physicsClientId=world.client)
        links[info[12].decode()] = j
        if info[2] != p.JOINT_FIXED:  # free the default velocity motors; joint friction set below
            p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, force=0, physicsClientId=world.client)
    world.objects[placed.id] = SimObject(placed.id, body, model, placed, links)
    del rng  # layout positions are deterministic already; kept for future jitter options


def _rest_on(
    world: World, placed: PlacedObject, model: AssetModel, occupied: dict[str, int]
) -> tuple[float, float, float]:
    """A resting position on or in the support named by ``placed.on``."""
    target = placed.on or ""
    host_id = target.split("/")[0]
    if host_id not in world.objects:
        if target in world.regions or target == world.table_id:
            return placed.position[0], placed.position[1], world.layout.table_height + 0.002
        raise GSRError(f"layout object {placed.id!r}: rests on {target!r}, which is not in the layout")
    host = world.objects[host_id]
    part = (
        resolve_part(host.model, world.graph, target)
        if "/" in target and world.graph.has_node(target)
        else ""
    )
    interior = host.model.interiors.get(part)
    rel = world.graph.edges_from(placed.id) if world.graph.has_node(placed.id) else iter(())
    inside = any(e.relation == "in" for e in rel) or (part and interior is not None)
    # what is inside a box and what stands on its lid are counted apart (a mug on a lid whose box holds
    # a book goes on the lid itself, not 6 cm above it as if stacked on something)
    key = f"{target}|{'in' if inside else 'on'}"
    k = occupied.get(key, 0)
    occupied[key] = k + 1
    if inside and interior is not None:
        link = host.links[interior.link]
        cx, cy, cz = interior.center
        sx, sy, sz = interior.size
        # a 3x3 grid of slots inside the interior so several objects do not start interpenetrating
        gx, gy = (k % 3 - 1) * sx / 3.2, (k // 3 % 3 - 1) * sy / 3.2
        if k == 0:
            gx = gy = 0.0
        art = host.model.articulations.get(part)
        if art is not None and art.kind == "drawer":
            # a drawer: in its front part (local -x, the handle's end), two rows of four, where a
            # hand put them through the opening and where it reaches them again under the drawer above
            row, col = k // 4 % 2, k % 4
            gx = -sx / 2 + DRAWER_SLOT_X + row * DRAWER_ROW_PITCH
            gy = (col - 1.5) * sy / 4.5
        elif not part:
            # a box: side by side across it, rows round its middle, where a later pick's hand fits
            slot = _box_slot(world, placed, model, host, link, (sx, sy, sz))
            if slot is not None:
                gx, gy = slot
        floor = world.to_world(host.body, link, (cx + gx, cy + gy, cz - sz / 2))
        return float(floor[0]), float(floor[1]), float(floor[2]) + 0.012 + 0.05 * (k // 9)
    link = host.links.get(host.model.part_links.get(part, ""), -1) if part else -1
    lo, hi = world.body_aabb(host.body) if link < 0 else world.aabb(host.body, link)
    cx, cy = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2
    return float(cx), float(cy), float(hi[2]) + 0.003 + 0.06 * k


def _box_slot(
    world: World,
    placed: PlacedObject,
    model: AssetModel,
    host: SimObject,
    link: int,
    size: tuple[float, float, float],
) -> tuple[float, float] | None:
    """Where ``placed``'s origin starts in a box's interior (offset from its middle, in the interior's
    frame): its slot of :func:`gsr.skills.box_slots.box_slots` among everything the layout puts in the
    same box; None when they do not all fit on the floor that way, or when one of them stands tall
    enough for a hand gripping its top to clear the walls (a mug: it is not taken from inside the box)."""
    box_yaw = world.yaw_of(host.body, link)
    interior = host.model.interiors[""]
    floor = world.to_world(host.body, link, (*interior.center[:2], interior.center[2] - size[2] / 2))[2]
    depth = float(world.aabb(host.body, link)[1][2]) - float(floor)  # floor to rim
    mine = None
    feet = []
    for o in world.layout.objects:
        if o.on != placed.on or not world.graph.has_node(o.id):
            continue
        if not any(e.relation == "in" for e in world.graph.edges_from(o.id)):
            continue
        m = model if o.id == placed.id else make_asset(o.asset, o.size, o.color)
        if m.extent[2] + HAND_OVER_TOP > depth - INSIDE_MARGIN:
            return None
        if o.id == placed.id:
            mine = len(feet)
        feet.append(turned_footprint(*footprint(m), o.yaw - box_yaw))
    if mine is None:
        return None
    slots = box_slots([h for _c, h in feet], np.array(size[:2]) / 2)
    if slots is None:
        return None
    origin = slots[mine] - feet[mine][0]
    return float(origin[0]), float(origin[1])


def _initial_joints(world: World, layout: Layout) -> None:
    import pybullet as p

    fractions: dict[tuple[str, str], float] = {}
    for placed in layout.objects:
        o = world.objects[placed.id]
        for name, value in placed.joint_states.items():
            part = name if name in o.model.articulations else ""
            if not part:
                node = f"{placed.id}/{name}"
                if world.graph.has_node(node):
                    part = resolve_part(o.model, world.graph, node)
            if part in o.model.articulations:
                fractions[(placed.id, part)] = float(value)
    for n in world.graph.nodes:
        target = n.parent if n.parent in world.objects else (n.id if n.id in world.objects else None)
        if target is None:
            continue
        o = world.objects[target]
        part = world.parts.get(n.id, (target, ""))[1]
        if "open" in n.states:
            part = part or o.model.open_part or ""
            fractions.setdefault((target, part), 1.0)
        if "on" in n.states:
            sw = part or o.model.switch_part or ""
            if sw in o.model.articulations and o.model.articulations[sw].kind == "button":
                world.powered[target] = True
            else:
                fractions.setdefault((target, sw), 1.0)
    for o in world.objects.values():
        for part, art in o.model.articulations.items():
            link = o.links[art.link]
            frac = fractions.get((o.id, part), 0.0)
            q = art.closed + frac * (art.open - art.closed)
            before = world.link_pose(o.body, link)[0]
            p.resetJointState(o.body, link, q, physicsClientId=world.client)
            _carry_riders(world, o, part, world.link_pose(o.body, link)[0] - before)
            if art.kind == "button":  # a spring: a weak position motor pulls the button back up
                p.setJointMotorControl2(
                    o.body,
                    link,
                    p.POSITION_CONTROL,
                    targetPosition=art.closed,
                    force=4.0,
                    positionGain=0.2,
                    physicsClientId=world.client,
                )
            else:
                p.setJointMotorControl2(
                    o.body,
                    link,
                    p.VELOCITY_CONTROL,
                    targetVelocity=0,
                    force=JOINT_FRICTION[art.kind],
                    physicsClientId=world.client,
                )


def _carry_riders(world: World, host: SimObject, part: str, shift: np.ndarray) -> None:
    """What the layout puts in or on a part that starts moved (a bowl in a drawer that starts open)
    moves with it: objects were set into the part where its link was before the joint was set."""
    import pybullet as p

    if float(np.linalg.norm(shift)) < 1e-6:
        return
    for o in world.objects.values():
        if world.parts.get(o.placed.on or "") == (host.id, part):
            pos, orn = p.getBasePositionAndOrientation(o.body, physicsClientId=world.client)
            p.resetBasePositionAndOrientation(
                o.body, tuple(np.array(pos) + shift), orn, physicsClientId=world.client
            )
