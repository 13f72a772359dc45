"""Turn one validated task into rows of the five sample types (see :mod:`gsr.datagen.schema`).

A task of L steps gives L+1 next-action rows (the last one says ``done``), L forward-prediction rows,
one inverse-action row, one scene-abstraction row and ``rephrasings`` goal-interpretation rows (the
same goal in different words: the rephrasing augmentation). Graph node and edge order is shuffled
per row (the object-order augmentation); ids follow the scene's naming style (name swaps).
"""

from __future__ import annotations

import json
import random
from typing import Any

from gsr.datagen.goals import GoalLiteral, goal_pddl
from gsr.datagen.language import instruction
from gsr.datagen.scene import Scene
from gsr.datagen.serialize import caption, graph_dict, node_states, positions, step_dict
from gsr.datagen.synth import PlannedTask

_DUMP = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False).encode


def goal_graph(scene: Scene, goal: tuple[GoalLiteral, ...]) -> dict[str, Any]:
    """The partial graph a goal requires: the nodes it names (with required states) and its relations."""
    required: dict[str, set[str]] = {}
    edges = []
    for lit in goal:
        for a in lit.args:
            required.setdefault(a, set())
        if lit.predicate in ("in", "on"):
            edges.append({"source": lit.args[0], "relation": lit.predicate, "target": lit.args[1]})
        elif lit.predicate == "open":
            required[lit.args[0]].add("open" if lit.positive else "closed")
        elif lit.predicate == "turned_on":
            required[lit.args[0]].add("on" if lit.positive else "off")
    # a part's parent must be present for the partial graph to be a valid SceneGraph
    for oid in list(required):
        parent = scene.by_id[oid].parent
        if parent:
            required.setdefault(parent, set())
    nodes = []
    for o in scene.objects:
        if o.id in required:
            node: dict[str, Any] = {"id": o.id, "category": o.category}
            if o.parent:
                node["parent"] = o.parent
            if required[o.id]:
                node["states"] = sorted(required[o.id])
            nodes.append(node)
    return {"nodes": nodes, "edges": edges}


def task_rows(
    scene: Scene, task: PlannedTask, rng: random.Random, meta: dict[str, Any], rephrasings: int = 2
) -> list[dict[str, Any]]:
    """All rows of one task; ``meta`` holds the envelope fields ``split``, ``heldout`` and ``task``."""
    rows: list[dict[str, Any]] = []
    horizon = len(task.steps)

    def row(kind: str, inp: dict[str, Any], out: dict[str, Any]) -> None:
        rows.append({"type": kind, **meta, "horizon": horizon, "input": _DUMP(inp), "output": _DUMP(out)})

    goal_text = goal_pddl(list(task.goal))
    said = instruction(scene, task.goal, rng)
    states = task.states
    seeds = [rng.getrandbits(32) for _ in states]  # one node order per state, shared by a row's graphs

    def graph(i: int) -> dict[str, Any]:
        return graph_dict(scene, states[i], random.Random(seeds[i]))

    # scene abstraction: perceived objects of the start state -> its graph
    where = positions(scene, states[0])
    objects = [
        {
            "id": o.id,
            "caption": caption(o, node_states(o, states[0]), rng),
            "position": list(where[o.id]),
            "size": list(o.size),
            "keypoints": list(o.keypoints),
        }
        for o in scene.objects
    ]
    rng.shuffle(objects)
    start = graph(0)
    row("scene_abstraction", {"objects": objects}, {"graph": start})
    # goal interpretation, in several wordings
    target = goal_graph(scene, task.goal)
    for k in range(rephrasings):
        text = said if k == 0 else instruction(scene, task.goal, rng)
        row(
            "goal_interpretation",
            {"instruction": text, "graph": start},
            {"goal": goal_text, "goal_graph": target},
        )
    # inverse action reasoning
    row(
        "inverse_action",
        {"start_graph": start, "goal_graph": graph(horizon)},
        {"plan": [step_dict(s, effects=False) for s in task.steps]},
    )
    # goal-conditioned next action (one per state, the last says done) and forward prediction
    history: list[dict[str, Any]] = []
    for t in range(horizon + 1):
        g = graph(t)
        step = task.steps[t] if t < horizon else None
        row(
            "next_action",
            {"instruction": said, "goal": goal_text, "graph": g, "history": list(history)},
            {"done": step is None, "step": step_dict(step) if step else None},
        )
        if step is None:
            break
        bare = step_dict(step, effects=False)
        after = graph_dict(scene, states[t + 1], random.Random(seeds[t]))  # same node order as the input
        full = step_dict(step)
        row(
            "forward_prediction",
            {"graph": g, "step": bare},
            {"graph": after, "add": full["add"], "delete": full["delete"]},
        )
        # the reasoner shows accepted steps with their (checked, hence true) effects: so does the history
        history.append(full)
    return rows
