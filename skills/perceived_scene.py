"""A perception-backed scene-graph source for a simulated world: what the robot's sensors say, not the truth.

Shared by the demo (``benchmarks/demo.py``) and the physical runner (``gsr bench run --physical --perceive``,
:mod:`gsr.skills.perceived_executor`). Each :meth:`PerceivedScene.observe` call

1. renders RGB-D and instance masks from the world's cameras (``gsr.skills.render_frame``, plus a mask for each
   door that is no graph node: :func:`frame_with_doors`; the masks stand in for a detector: ids and
   labels, no geometry) and runs :func:`gsr.perception.perceive` on them (fused views);
2. adds the robot's *known map*: the table's named regions (LIBERO ``stove_front_region`` ...) are not
   visible things, so their nodes come from the map and an object perceived on the table inside a region's
   rectangle is on that region (the same rule as the simulator's ground truth);
3. adds *proprioception*: an object both fingers touch is held (grasp state, not vision): it gets the
   ``held`` state and loses any support edge; if the hand hides it, its node comes from the last belief;
4. merges the result into the previous belief with :func:`gsr.perception.update_belief` (objects inside a
   container that is now closed, or hidden behind something nearer in every camera, such as the arm,
   are remembered, marked ``observed: False``);
5. keeps the states no sensor sees (power: on/off) from its prior (:func:`with_unsensed_states`).

:func:`observable_view` is the comparison rule of the closed loop: only facts a sensor can confirm now
(support edges and ``open`` states of nodes seen in this observation, plus ``held`` from the gripper).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from gsr.perception import perceive, update_belief
from gsr.perception.detect import load_detector
from gsr.perception.frame import Frame, InstanceLabel
from gsr.perception.match import match_nodes
from gsr.perception.rgbd import View, detect_frames
from gsr.perception.track import UNKNOWN, Tracker, rename_graph
from gsr.skills.camera import RGBD, default_views, labelled_masks, no_masks, render_frame
from gsr.skills.executor import symbolic_view
from gsr.skills.sim_graph import scene_graph_from_sim, support_of

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.scene_graph import Edge, Node, SceneGraph

if TYPE_CHECKING:
    from gsr.perception import Frame, PerceptionParams
    from gsr.skills.camera import CameraSpec
    from gsr.skills.world import World

#: The cameras perceived (gsr.skills.camera.default_views names); the first one's RGB is kept for reports.
VIEWS = ("front", "top", "left", "right")
_SUPPORT = ("on", "in")
#: Node states the sensors confirm: articulation (cameras) and the grasp (gripper).
SENSED_STATES = frozenset({"open", "held"})
#: Node states no camera here can see (power: nothing in the rendering shows a stove or lamp is on); the
#: belief keeps them from its prior (the last belief, or the graph the robot's own step should produce).
UNSENSED_STATES = frozenset({"on", "off"})


class PerceivedScene:
    """Scene graphs of one world from its cameras, the known map and the gripper; keeps the belief.

    By default perception sees RGB-D and the cameras only: a detector (:func:`gsr.perception.detect.load_detector`)
    segments and names the objects, node ids are perception's own (kept across observations by a
    :class:`gsr.perception.track.Tracker`), and :attr:`binding` says which simulated body each perceived
    node is, for the skills to act on (:func:`bind_to_world`). ``oracle_masks=True`` is the earlier path:
    the simulator's segmentation with the task graph's ids and labels stands in for the detector."""

    def __init__(
        self,
        world: World,
        views: Sequence[str] = VIEWS,
        params: PerceptionParams | None = None,
        oracle_masks: bool = False,
        detector: Any = None,
    ) -> None:

        specs = default_views(world)
        unknown = [v for v in views if v not in specs]
        if unknown or not views:
            raise GSRError(f"unknown camera view(s) {unknown}; choose from {sorted(specs)}")
        self.world = world
        self.specs = [specs[v] for v in views]
        self.params = params
        self.oracle_masks = oracle_masks
        self.detector = detector
        if not oracle_masks and detector is None:
            self.detector = load_detector()
        self.tracker = None if oracle_masks else _tracker()
        #: perceived node id -> the world's node id of the body it is (identity with oracle masks)
        self.binding: dict[str, str] = {}
        self.belief: SceneGraph | None = None
        self.last_rgb: np.ndarray | None = None  # the first view's RGB of the latest observation
        self.observations = 0

    def frames(self) -> list[Frame]:
        """Render every camera now: the detector's frames (no ids), or the simulator's labelled masks."""
        if self.oracle_masks:
            return [frame_with_doors(self.world, spec) for spec in self.specs]

        return detect_frames([self_filtered_view(self.world, spec) for spec in self.specs], self.detector)

    def observe(self, expected: SceneGraph | None = None) -> SceneGraph:
        """Perceive the world now and merge it into the belief; the new belief.

        ``expected`` (the graph the robot's last step should have produced) is the prior for what no
        sensor sees: states in ``UNSENSED_STATES``, and where a remembered object the robot just let go
        of is (:func:`with_remembered_support`); without it the previous belief is."""
        frames = self.frames()
        self.last_rgb = frames[0].rgb
        observed = perceive(frames, self.params)
        if self.oracle_masks:
            observed = without_helper_parts(observed, self.world)
            held = held_objects(self.world)
        else:
            assert self.tracker is not None
            observed = self.tracker.assign(observed, self.belief)
            now = bind_to_world(observed, self.world)
            # remembered nodes keep their body unless a node seen now is that body
            kept = {p: w for p, w in self.binding.items() if p not in now and w not in now.values()}
            self.binding = {**kept, **now}
            to_perceived = {w: p for p, w in self.binding.items()}
            held = {to_perceived[w] for w in held_objects(self.world) if w in to_perceived}
            observed, held = self._keep_grasped_id(observed, held, expected)
            observed = self._keep_released_id(observed, held, expected)
        observed = with_map_regions(
            observed, self.world, table_only=not self.oracle_masks, previous=self.belief
        )
        observed = with_held(observed, held, self.belief, None if not self.oracle_masks else self.world.graph)
        prior = expected if expected is not None else self.belief
        observed = with_unseen_parts(observed, self.belief, prior)
        belief = with_unsensed_states(update_belief(self.belief, observed, frames), prior)
        self.belief = with_remembered_support(belief, held, prior)
        self.observations += 1
        return self.belief

    def _keep_grasped_id(
        self, observed: SceneGraph, held: set[str], expected: SceneGraph | None
    ) -> tuple[SceneGraph, set[str]]:
        """The object in the gripper keeps the id of the object the robot's own step grasped.

        Lifted, an object is seen from another side and may be named otherwise (a bottle read as a mug),
        so the tracker gives it a fresh id; but the robot knows what it picked up (its step, ``held`` in
        the expected graph) and the gripper says it holds one object: that object is the one picked, with
        the category and colour it had before it was lifted, and the pose and box seen now."""
        grasped = {n.id for n in expected.nodes if "held" in n.states} if expected is not None else set()
        ids = {n.id for n in observed.nodes}
        if len(held) != 1 or len(grasped) != 1 or held == grasped:
            return observed, held
        (new,), (old,) = held, grasped
        if old in ids or new not in ids:
            return observed, held

        self.binding[old] = self.binding.pop(new)
        return self._same_object(observed, new, old), {old}

    def _keep_released_id(
        self, observed: SceneGraph, held: set[str], expected: SceneGraph | None
    ) -> SceneGraph:
        """The object the robot's own step just let go of keeps its id where the step put it.

        Set down in a drawer or a box, an object is partly hidden by the walls and seen from above, so
        the tracker may not know it again (another size, another colour word) and gives it a fresh id.
        But the robot knows what it released (held in the belief, not held now) and where the step put
        it (its ``on``/``in`` edge in the expected graph): one new node of the same kind on or in that
        place, and no node with the old id, is that object, with what it was and where it is now."""
        if expected is None or self.belief is None:
            return observed
        released = {n.id for n in self.belief.nodes if "held" in n.states} - held
        if len(released) != 1:
            return observed
        (old,) = released
        ids = {n.id for n in observed.nodes}
        before = self.belief.node_map().get(old)
        placed = {
            (e.relation, e.target) for e in expected.edges if e.source == old and e.relation in ("on", "in")
        }
        if old in ids or before is None or not placed:
            return observed
        known = {n.id for n in self.belief.nodes}
        fresh = [
            n
            for n in observed.nodes
            if n.id not in known
            and n.parent is None
            and n.category in (before.category, UNKNOWN)
            and any((e.relation, e.target) in placed for e in observed.edges if e.source == n.id)
        ]
        if len(fresh) != 1:
            return observed
        if fresh[0].id in self.binding:  # else the released id keeps the body it was bound to
            self.binding[old] = self.binding.pop(fresh[0].id)
        return self._same_object(observed, fresh[0].id, old)

    def _same_object(self, observed: SceneGraph, new: str, old: str) -> SceneGraph:
        """``observed`` with node ``new`` renamed ``old``: what it is from the belief's ``old`` (category,
        colour ...), where it is and how it looks now (pose, box, states, size) from the cameras."""
        renamed = rename_graph(observed, {new: old})
        before = (self.belief.node_map() if self.belief is not None else {}).get(old)
        if before is None:
            return renamed
        seen = renamed.node(old)
        geometry = {
            k: v for k, v in seen.attributes.items() if k.startswith("size_") or k in ("points", "views")
        }
        kept = before.model_copy(
            update={
                "pose": seen.pose,
                "bbox": seen.bbox,
                "states": seen.states,
                "attributes": {**{k: v for k, v in before.attributes.items() if k != "observed"}, **geometry},
            }
        )
        return renamed.with_nodes([kept])

    def world_id(self, node_id: str) -> str:
        """The world's node id of a perceived node (for the skills), or the id itself when unbound."""
        return node_id if self.oracle_masks else self.binding.get(node_id, node_id)

    def in_world_ids(self, graph: SceneGraph) -> SceneGraph:
        """A perceived graph in the world's ids (for scoring against the task's goal)."""
        if self.oracle_masks:
            return graph

        mapping = {
            n.id: self.binding.get(n.id, f"unbound_{n.id}")
            for n in graph.nodes
            if not n.attributes.get("map")
        }
        return rename_graph(graph, mapping)

    def in_perceived_ids(self, graph: SceneGraph) -> SceneGraph:
        """A world graph (the simulator's truth) in the perceived ids (to check a perceived goal on it)."""
        if self.oracle_masks:
            return graph

        back = {w: p for p, w in self.binding.items()}
        regions = set(self.world.regions)
        mapping = {n.id: back.get(n.id, f"unseen_{n.id}") for n in graph.nodes if n.id not in regions}
        return rename_graph(graph, mapping)


def _tracker() -> Any:
    return Tracker()


def self_filtered_view(world: World, spec: CameraSpec) -> Any:
    """One camera's RGB-D with the robot's own body removed (depth 0 there), as a robot filters itself
    out of its sensor data with its own model at its joint state; nothing else of the simulator's
    segmentation is used (no masks: the detector segments)."""
    frame = render_frame(world, spec, masks=no_masks, robot_free=True)
    return View(frame.rgb, frame.depth, frame.camera)


def bind_to_world(graph: SceneGraph, world: World) -> dict[str, str]:
    """Which simulated body (world node id) each perceived node is: the one its box overlaps most.

    This is the simulator's stand-in for a robot reaching to the place perception reported: the skills
    act on bodies, so a perceived ``bowl_1`` must be resolved to the body at its place. It reads the
    bodies' boxes only, after perception, and never feeds anything back into the perceived graph.
    Among overlapping pairs the same category wins (a perceived drawer is the drawer it overlaps, not a
    cabinet-top part that spans the drawer's body: the skills would open what the node names)."""
    return match_nodes(graph, scene_graph_from_sim(world), same_category=1.0)


def frame_with_doors(world: World, spec: CameraSpec) -> Frame:
    """``gsr.skills.render_frame`` plus one mask per door that the scene graph has no part node for.

    A microwave's door is a link of the microwave, not a node, so ``render_frame`` labels its pixels as
    the microwave and perception can only judge the microwave by its top surface (a front door stays
    unseen). A detector segments a door as such: here its pixels get their own label (``<object>/door``,
    category ``door``, parent the object), so perception measures the door angle and the object takes
    the door's open/closed state; :func:`without_helper_parts` drops the door node afterwards.
    """
    return render_frame(world, spec, masks=masks_with_doors)


def masks_with_doors(world: World, img: RGBD) -> tuple[np.ndarray, dict[int, InstanceLabel]]:
    """:func:`gsr.skills.camera.labelled_masks` plus a mask for each door that is no graph node (a ``MaskSource``)."""
    masks, labels = labelled_masks(world, img)
    parts = {(obj, part) for obj, part in world.parts.values()}
    for oid in sorted(world.objects):
        o = world.objects[oid]
        door = o.model.open_part
        art = o.model.articulations.get(door or "")
        if art is None or art.kind != "door" or (oid, door) in parts or not world.graph.has_node(oid):
            continue
        pixels = (img.body == o.body) & (img.link == o.links[art.link])
        if pixels.any():
            k = len(labels)
            masks = np.where(pixels, k, masks)
            labels[k] = InstanceLabel(id=f"{oid}/{door}", category="door", parent=oid)
    return masks, labels


def without_helper_parts(graph: SceneGraph, world: World) -> SceneGraph:
    """The graph without part nodes the task graph does not have (the doors of :func:`frame_with_doors`).

    Only parts: a ground perception found itself (``table`` from background pixels) stays."""
    extra = {n.id for n in graph.nodes if n.parent is not None and not world.graph.has_node(n.id)}
    if not extra:
        return graph
    return graph.model_copy(
        update={
            "nodes": tuple(n for n in graph.nodes if n.id not in extra),
            "edges": tuple(e for e in graph.edges if e.source not in extra and e.target not in extra),
        }
    )


def held_objects(world: World) -> set[str]:
    """Objects both fingers touch now (the gripper's grasp state, not vision)."""

    # boxes=[]: skip the containment test, only the finger contacts matter here
    return {
        oid
        for oid, o in world.objects.items()
        if not o.model.fixed and support_of(world, oid, boxes=[]) == ("held", "")
    }


def with_map_regions(
    graph: SceneGraph, world: World, table_only: bool = False, previous: SceneGraph | None = None
) -> SceneGraph:
    """Add the table's named regions (map nodes) and move objects on the table onto the region they are in.

    ``table_only`` (perception without the simulator's ids): only regions of the table itself come from
    the map — a drawer or a cabinet top that LIBERO also names as a region is perceived, not given — and
    the table is whichever ground (``table``/``floor``) perception found.

    ``previous`` (the belief before this observation): an object that stood still (its centre within
    ``REGION_STAY`` of where the belief had it) keeps the region it was on while its perceived box still
    meets that region, and stays on the plain table while its box still reaches out of the region its
    centre now seems in. The centre rule alone flips an object standing on a region's edge (LIBERO places
    some exactly there) with every millimetre the measured centre moves as the arm hides another part of
    it; an object the robot moved is placed by the centre rule."""
    regions = [
        nid
        for nid in sorted(world.regions)
        if world.graph.has_node(nid) and not (table_only and (nid in world.parts or nid in world.objects))
    ]
    if not regions:
        return graph
    grounds = {world.table_id} | (
        {n.id for n in graph.nodes if n.category in ("table", "floor")} if table_only else set()
    )
    ground = next((n.id for n in graph.nodes if n.category in ("table", "floor")), None)
    ids = {n.id for n in graph.nodes}
    added = []
    for nid in regions:
        if nid in ids:
            continue
        node = world.graph.node(nid)
        update: dict[str, Any] = {"attributes": {**node.attributes, "map": True}}
        if table_only and node.parent == world.table_id and ground is not None:
            update["parent"] = ground  # the region belongs to the table perception found
        added.append(node.model_copy(update=update))
    nodes = graph.node_map()
    before = {
        e.source: e.target for e in (previous.edges if previous is not None else ()) if e.relation == "on"
    }
    where = previous.node_map() if previous is not None else {}
    edges = []
    for e in graph.edges:
        node = nodes.get(e.source)
        if e.relation == "on" and e.target in grounds and node is not None and node.pose is not None:
            p = node.pose.position
            region = next((r for r in regions if _inside(world.regions[r].bounds, p.x, p.y)), None)
            was = before.get(e.source)
            if _stayed(node, where.get(e.source)):
                # where it stood, on a region's edge: the region it was on while its box still meets that
                # region; the plain ground while its box still reaches out of the region it now seems in
                if region is None and was in regions and _box_meets(node, world.regions[was].bounds):
                    region = was
                elif (
                    region is not None
                    and was in grounds
                    and not _box_within(node, world.regions[region].bounds)
                ):
                    region = None
            if region is not None:
                e = Edge(source=e.source, relation="on", target=region)
        edges.append(e)
    return graph.model_copy(
        update={
            "nodes": tuple(sorted((*graph.nodes, *added), key=lambda n: n.id)),
            "edges": tuple(sorted(set(edges), key=Edge.key)),
        }
    )


#: An object whose perceived centre moved less than this (m) since the last belief stood still.
REGION_STAY = 0.02


def _stayed(node: Node, before: Node | None) -> bool:
    """Whether the node's centre is within ``REGION_STAY`` of where the previous belief had it."""
    if before is None or before.pose is None or node.pose is None:
        return False
    a, b = node.pose.position, before.pose.position
    return float(np.hypot(a.x - b.x, a.y - b.y)) <= REGION_STAY


def _box_within(node: Node, bounds: tuple[float, float, float, float]) -> bool:
    """Whether a node's box (its centre when it has none) lies wholly inside a region's rectangle."""
    if node.bbox is None:
        p = node.pose.position  # type: ignore[union-attr]
        return _inside(bounds, p.x, p.y)
    lo, hi = node.bbox.min, node.bbox.max
    return _inside(bounds, lo.x, lo.y) and _inside(bounds, hi.x, hi.y)


def _box_meets(node: Node, bounds: tuple[float, float, float, float]) -> bool:
    """Whether a node's box (its centre when it has none) meets a region's rectangle."""
    if node.bbox is None:
        p = node.pose.position  # type: ignore[union-attr]
        return _inside(bounds, p.x, p.y)
    x0, y0, x1, y1 = bounds
    lo, hi = node.bbox.min, node.bbox.max
    return lo.x <= x1 and hi.x >= x0 and lo.y <= y1 and hi.y >= y0


def _inside(bounds: tuple[float, float, float, float], x: float, y: float) -> bool:
    x0, y0, x1, y1 = bounds
    return x0 <= x <= x1 and y0 <= y <= y1


def with_held(
    graph: SceneGraph, held: set[str], belief: SceneGraph | None, fallback: SceneGraph | None = None
) -> SceneGraph:
    """Mark ``held`` objects (from the gripper) held and unsupported; a hidden held object comes from memory."""
    if not held:
        return graph
    nodes = graph.node_map()
    known = belief.node_map() if belief is not None else {}
    spare = fallback.node_map() if fallback is not None else {}
    out: list[Node] = [n for n in graph.nodes if n.id not in held]
    for oid in sorted(held):
        node = nodes.get(oid) or known.get(oid) or spare.get(oid)
        if node is None:
            continue
        states = tuple(sorted({*node.states, "held"}))
        out.append(node.model_copy(update={"states": states}))
    edges = [e for e in graph.edges if not (e.source in held and e.relation in _SUPPORT)]
    return graph.model_copy(
        update={
            "nodes": tuple(sorted(out, key=lambda n: n.id)),
            "edges": tuple(sorted(set(edges), key=Edge.key)),
        }
    )


def with_unseen_parts(graph: SceneGraph, belief: SceneGraph | None, prior: SceneGraph | None) -> SceneGraph:
    """Parts of objects seen now that the cameras do not pick out this time stay, unobserved.

    A drawer pushed shut is flush with its cabinet and need not show as a part of its own; the cabinet is
    seen, so its drawer is still there. Its ``open``/``closed`` state comes from ``prior`` (what the robot's
    own step should have done), else from the last belief; it is marked ``observed: False``, so the closed
    loop does not count it as confirmed."""
    if belief is None:
        return graph
    ids = {n.id for n in graph.nodes}
    seen_now = {n.id for n in graph.nodes if n.attributes.get("observed", True) is not False}
    before = prior.node_map() if prior is not None else {}
    added = []
    for n in belief.nodes:
        if n.parent is None or n.id in ids or n.parent not in seen_now:
            continue
        states = before[n.id].states if n.id in before else n.states
        added.append(
            n.model_copy(update={"states": states, "attributes": {**n.attributes, "observed": False}})
        )
    if not added:
        return graph
    return graph.model_copy(update={"nodes": tuple(sorted((*graph.nodes, *added), key=lambda n: n.id))})


def with_unsensed_states(graph: SceneGraph, prior: SceneGraph | None) -> SceneGraph:
    """Each node's unsensed states (power) taken from ``prior``; sensed states stay as observed."""
    if prior is None:
        return graph
    before = prior.node_map()
    nodes = []
    for n in graph.nodes:
        old = before.get(n.id)
        carried = {s for s in old.states if s in UNSENSED_STATES} if old is not None else set()
        states = tuple(sorted({s for s in n.states if s not in UNSENSED_STATES} | carried))
        nodes.append(n if states == n.states else n.model_copy(update={"states": states}))
    return graph.model_copy(update={"nodes": tuple(nodes)})


def with_remembered_support(graph: SceneGraph, held: set[str], prior: SceneGraph | None) -> SceneGraph:
    """Remembered nodes get ``held`` only from the gripper now, and a support edge from ``prior`` if none.

    A node the cameras no longer see is carried from the last belief, grasp state included; but only the
    gripper says what is held now. An object just released where no camera sees it (a cube put into a
    box, under the arm) is where the robot's own step put it: the prior's support edge."""
    remembered = {n.id for n in graph.nodes if n.attributes.get("observed", True) is False}
    stale = {n.id for n in graph.nodes if "held" in n.states and n.id not in held}
    if not remembered and not stale:
        return graph
    nodes = tuple(
        n.model_copy(update={"states": tuple(s for s in n.states if s != "held")}) if n.id in stale else n
        for n in graph.nodes
    )
    ids = {n.id for n in nodes}
    supported = {e.source for e in graph.edges if e.relation in _SUPPORT}
    carried = [
        e
        for e in (prior.edges if prior is not None else ())
        if e.relation in _SUPPORT
        and e.source in remembered
        and e.source not in supported
        and e.source not in held
        and e.target in ids
    ]
    return graph.model_copy(
        update={"nodes": nodes, "edges": tuple(sorted({*graph.edges, *carried}, key=Edge.key))}
    )


def observed_ids(graph: SceneGraph) -> set[str]:
    """Nodes the latest observation confirms: seen now (not remembered, not a map node) or held."""
    return {
        n.id
        for n in graph.nodes
        if "held" in n.states
        or (n.attributes.get("observed", True) is not False and not n.attributes.get("map"))
    }


def observable_view(graph: SceneGraph, confirmed: set[str]) -> SceneGraph:
    """The symbolic part a sensor can confirm: confirmed nodes' open/on/held states and support edges."""
    sym = symbolic_view(graph)
    sym = sym.model_copy(
        update={
            "nodes": tuple(
                n.model_copy(
                    update={"attributes": {}, "states": tuple(s for s in n.states if s in SENSED_STATES)}
                )
                for n in sym.nodes
            )
        }
    )
    edges = tuple(e for e in sym.edges if e.source in confirmed)
    keep = {n.id for n in sym.nodes if n.id in confirmed} | {e.target for e in edges}
    # a kept part's object stays too (a drawer's cabinet, transitively), or the part's parent would dangle
    parent = {n.id: n.parent for n in sym.nodes}
    for node_id in list(keep):
        while parent.get(node_id) is not None and parent[node_id] not in keep:
            node_id = parent[node_id]
            keep.add(node_id)
    # an unconfirmed node kept for an edge or a part stays bare (its own states are not confirmed)
    nodes = tuple(
        n if n.id in confirmed else n.model_copy(update={"states": ()}) for n in sym.nodes if n.id in keep
    )
    return SceneGraph(nodes=nodes, edges=edges)


#: Predicates a sensor confirms: support and articulation from the cameras, holding from the gripper.
#: (``turned_on`` is not among them: nothing in the rendering shows whether a stove or lamp is on.)
OBSERVABLE_PREDICATES = frozenset({"on", "in", "open", "holding"})


def contradicted_effects(diagnosis: Any, graph: SceneGraph, domain: Any) -> list[str]:
    """A checked step's true effects on observable predicates that the observed graph contradicts."""
    atoms = state_from_graph(graph, domain).atoms
    wrong = [f"{a}" for a in diagnosis.add if a.predicate in OBSERVABLE_PREDICATES and a not in atoms]
    wrong += [f"(not {a})" for a in diagnosis.delete if a.predicate in OBSERVABLE_PREDICATES and a in atoms]
    return sorted(wrong)
