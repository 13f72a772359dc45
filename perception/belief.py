"""Object permanence across observations: what a closed container hides is still there.

A camera cannot see a bowl inside a closed drawer. Perceiving each frame in isolation would drop it,
and a goal such as "the bowl in the bottom drawer, drawer closed" could never be verified. ``update_belief``
merges a new observation into the previous belief: every node seen now comes from the observation; a node
*not* seen now is kept, with its support edge and marked ``observed: False``, only when its absence is
explained — it was last inside (or on something inside) a container that is now observed closed. Any
other disappearance is believed: the object is gone from view for a reason we cannot explain, so it is
dropped rather than invented.
"""

from __future__ import annotations

from gsr.scene_graph import Edge, Node, SceneGraph

_SUPPORT = ("in", "on")


def _support(graph: SceneGraph) -> dict[str, Edge]:
    return {e.source: e for e in graph.edges if e.relation in _SUPPORT}


def _hidden_by_closed_container(node_id: str, belief: SceneGraph, observed: SceneGraph) -> bool:
    """True when, following support edges down from ``node_id`` in the belief, an ``in`` edge reaches a
    container that the new observation shows closed."""
    support = _support(belief)
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


def update_belief(belief: SceneGraph | None, observed: SceneGraph) -> SceneGraph:
    """The new belief: the observation plus the occluded objects it explains (see the module docstring)."""
    if belief is None:
        return observed
    seen = {n.id for n in observed.nodes}
    kept: list[Node] = []
    for node in belief.nodes:
        if node.id in seen or node.parent is not None:
            continue
        if _hidden_by_closed_container(node.id, belief, observed):
            kept.append(node.model_copy(update={"attributes": {**node.attributes, "observed": False}}))
    if not kept:
        return observed
    kept_ids = {n.id for n in kept}
    nodes = {n.id for n in observed.nodes} | kept_ids
    carried = [
        e
        for e in belief.edges
        if e.source in kept_ids and e.relation in _SUPPORT and e.target in nodes  # where it was last seen
    ]
    return observed.model_copy(
        update={
            "nodes": tuple(sorted((*observed.nodes, *kept), key=lambda n: n.id)),
            "edges": tuple(sorted({*observed.edges, *carried}, key=Edge.key)),
            "metadata": {**observed.metadata, "remembered": sorted(kept_ids)},
        }
    )
