"""Closed-loop recovery for a refused pick: set the neighbours in the hand's way aside, then pick again.

A pick the motion planner refuses (``blocked``) names what its candidates ran into
(:func:`gsr.skills.grasping.in_the_way`: a mug packed beside a cube in a box, a box beside a cube on the
desk; never a fixture or the object's own container). The executor then sets the most often named
neighbour aside (a neighbour that carries something, a box with a box on it, from the top down): two ordinary checked steps, ``(pick N S)`` and ``(place_on N table)``, the release
spot a free one the arm reaches that keeps the hand's room round the object free
(:data:`HAND_ROOM`); and tries the pick again. At most :data:`MAX_CLEARANCES` neighbours per step.
The agent is told that the scene now differs from its plan (a neighbour moved) and replans from the
observed graph; the episode's step outcomes list the clearance steps with their own diagnoses.
"""

from __future__ import annotations

import re
import time

import numpy as np
from gsr.skills.grasping import place
from gsr.skills.library import settle_released
from gsr.skills.motion import Motion
from gsr.skills.result import Failure, SkillError, SkillResult
from gsr.skills.sim_graph import support_of
from gsr.skills.world import World

from gsr.scene_graph import SceneGraph
from gsr.step import Step

#: Neighbours set aside at most for one refused pick (3: a cube packed behind a cube, a box beside
#: the box, gsrgen_sod_complex_18; the episode cap bounds the total).
MAX_CLEARANCES = 3
#: Room (m) kept free round the object's footprint on the table: the hand reaches about 10 cm to
#: either side of its grasp point along its closing axis.
HAND_ROOM = 0.10

_NAMED = re.compile(r"\(in the way: ([^)]*)\)")


def blockers(message: str, world: World, graph: SceneGraph) -> list[str]:
    """The movable neighbours a refused pick's diagnosis names as in the way, most often named first,
    that the observed graph shows resting on or in something with nothing on them (so a pick of them
    is a valid step). A neighbour something stands on (a box carrying a box) is taken apart from the
    top: what stands highest on it comes in its place (set aside first; the pick is tried again, and
    if the neighbour is still in the way it is named again, now with nothing on it)."""
    found = _NAMED.search(message)
    if not found:
        return []
    rests = {e.source for e in graph.edges if e.relation in ("on", "in")}
    on_it: dict[str, list[str]] = {}
    for e in graph.edges:
        if e.relation == "on":
            on_it.setdefault(e.target, []).append(e.source)
    out: list[str] = []
    for name in (n.strip() for n in found.group(1).split(",")):
        top = stack_top(on_it, name)
        if top is not None and top in world.objects and top in rests and top not in out:
            out.append(top)
    return out


def stack_top(on_it: dict[str, list[str]], node: str) -> str | None:
    """What stands highest on ``node`` (``on_it``: what stands on each thing), following the first of
    each level's objects; ``node`` itself when nothing stands on it; None on a cycle."""
    seen = {node}
    while on_it.get(node):
        node = sorted(on_it[node])[0]
        if node in seen:
            return None
        seen.add(node)
    return node


def support_step(graph: SceneGraph, node: str) -> Step | None:
    """``(pick node support)`` for the node's support in the observed graph, or None."""
    for e in graph.edges:
        if e.source == node and e.relation in ("on", "in"):
            return Step("pick", (node, e.target))
    return None


def keep_clear_around(world: World, node: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """The table rectangle (centre, half sizes) round ``node``'s footprint that the hand needs free."""
    lo, hi = world.body_aabb(world.objects[node].body)
    return [((lo[:2] + hi[:2]) / 2, (hi[:2] - lo[:2]) / 2 + HAND_ROOM)]


def set_aside(
    world: World, node: str, keep_clear: list[tuple[np.ndarray, np.ndarray]], budget: int
) -> SkillResult:
    """Put the held ``node`` on the bare table, out of the ``keep_clear`` rectangles; the skill's result
    (checked: it must rest on the table afterwards)."""
    t0 = time.perf_counter()
    m = Motion(world, budget)
    name = f"(place_on {node} {world.table_id})"
    try:
        if support_of(world, node) != ("held", ""):
            raise SkillError(Failure.GRASP_SLIPPED, f"{node} is not in the hand")
        obj = world.objects[node]
        place(world, m, obj, world.table_id, "on", keep_clear=keep_clear)
        settle_released(world, m, obj.body)
        got = support_of(world, node)
        if got != ("on", world.table_id):
            where = f"{got[0]} {got[1]}".strip() if got else "nowhere (still moving)"
            raise SkillError(Failure.NOT_ACHIEVED, f"{node} ended {where}, not on {world.table_id}")
    except SkillError as exc:
        return SkillResult(
            "place_on", name, False, exc.failure, exc.message, m.used, time.perf_counter() - t0
        )
    return SkillResult(
        "place_on",
        name,
        True,
        None,
        "",
        m.used,
        time.perf_counter() - t0,
        {"support": f"on {world.table_id}"},
    )
