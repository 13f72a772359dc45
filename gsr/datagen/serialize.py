"""Cheap serialisation of generated scenes: graph dicts, steps, positions and object captions.

Samples are built millions of times, so graphs are plain dicts in the ``SceneGraph`` JSON layout
(``SceneGraph.model_validate`` accepts every one; the tests check it) built from per-scene cached
static node dicts plus the state's support edges and door/power/hand states, not pydantic objects.
"""

from __future__ import annotations

import random
from typing import Any

from gsr.datagen.scene import Scene, SceneObject
from gsr.pddl.model import Atom
from gsr.step import Step


def _base(o: SceneObject) -> dict[str, Any]:
    node: dict[str, Any] = {"id": o.id, "category": o.category}
    attrs: dict[str, Any] = {}
    if o.color:
        attrs["color"] = o.color
    if o.material:
        attrs["material"] = o.material
    if o.level is not None:
        attrs["level"] = o.level
    if attrs:
        node["attributes"] = attrs
    if o.parent:
        node["parent"] = o.parent
    return node


def _bases(scene: Scene) -> list[dict[str, Any]]:
    if not scene.node_bases:
        scene.node_bases = [_base(o) for o in scene.objects]
    return scene.node_bases


def node_states(o: SceneObject, atoms: frozenset[Atom]) -> list[str]:
    """The node's state words in a state: open/closed, on/off, held (sorted, as Node stores them)."""
    states = []
    if "openable" in o.affordances:
        states.append("open" if Atom("open", (o.id,)) in atoms else "closed")
    if "switchable" in o.affordances:
        states.append("on" if Atom("turned_on", (o.id,)) in atoms else "off")
    if Atom("holding", (o.id,)) in atoms:
        states.append("held")
    return sorted(states)


def graph_dict(
    scene: Scene, atoms: frozenset[Atom], rng: random.Random | None = None
) -> dict[str, list[dict[str, Any]]]:
    """The scene in a state as a SceneGraph JSON dict; ``rng`` shuffles node and edge order (augmentation)."""
    nodes = []
    for o, base in zip(scene.objects, _bases(scene), strict=True):
        states = node_states(o, atoms)
        nodes.append({**base, "states": states} if states else base)
    edges = [
        {"source": a.args[0], "relation": a.predicate, "target": a.args[1]}
        for a in atoms
        if a.predicate in ("on", "in")
    ]
    edges.sort(key=lambda e: (e["source"], e["relation"], e["target"]))
    if rng is not None:
        # parts must still follow their parent for readability; shuffle top-level objects as blocks
        nodes = _shuffled_blocks(nodes, rng)
        rng.shuffle(edges)
    return {"nodes": nodes, "edges": edges}


def _shuffled_blocks(nodes: list[dict[str, Any]], rng: random.Random) -> list[dict[str, Any]]:
    blocks: list[list[dict[str, Any]]] = []
    for n in nodes:
        if "parent" in n and blocks:
            blocks[-1].append(n)
        else:
            blocks.append([n])
    rng.shuffle(blocks)
    return [n for b in blocks for n in b]


def atom_text(atom: Atom) -> str:
    """``(on a b)``."""
    return f"({' '.join((atom.predicate, *atom.args))})"


def step_dict(step: Step, effects: bool = True) -> dict[str, Any]:
    """A step as ``{action, args[, add, delete]}`` with atoms as PDDL text."""
    out: dict[str, Any] = {"action": step.action, "args": list(step.args)}
    if effects:
        out["add"] = [atom_text(a) for a in step.add or ()]
        out["delete"] = [atom_text(a) for a in step.delete or ()]
    return out


# ------------------------------------------------------------ positions and captions (scene abstraction)

_SIZE_WORDS = ((0.0004, "small"), (0.004, "medium-sized"), (float("inf"), "large"))


def size_word(o: SceneObject) -> str:
    """small / medium-sized / large from the object's volume."""
    volume = o.size[0] * o.size[1] * o.size[2]
    return next(w for limit, w in _SIZE_WORDS if volume < limit)


def positions(scene: Scene, atoms: frozenset[Atom]) -> dict[str, tuple[float, float, float]]:
    """Base-centre positions consistent with the state: things in a container sit on its floor,
    things on a supporter on its top, held things at the gripper; everything else at home."""
    support = {a.args[0]: (a.predicate, a.args[1]) for a in atoms if a.predicate in ("on", "in")}
    held = {a.args[0] for a in atoms if a.predicate == "holding"}
    out: dict[str, tuple[float, float, float]] = {}

    def pos(oid: str, depth: int = 0) -> tuple[float, float, float]:
        if oid in out:
            return out[oid]
        o = scene.by_id[oid]
        if oid in held:
            p = (0.25, 0.0, 0.35)
        elif oid in support and support[oid][1] != "table" and depth < 8:
            rel, target = support[oid]
            t = pos(target, depth + 1)
            tobj = scene.by_id[target]
            # a deterministic small offset per object keeps co-located things apart
            dx = (sum(map(ord, oid)) % 7 - 3) * 0.01
            z = t[2] + 0.01 if rel == "in" else t[2] + (tobj.size[2] if tobj.role != "part" else 0.02)
            p = (round(t[0] + dx, 3), round(t[1] - dx, 3), round(z, 3))
        else:
            p = o.home
        out[oid] = p
        return p

    for o in scene.objects:
        pos(o.id)
    return out


def caption(o: SceneObject, states: list[str], rng: random.Random) -> str:
    """A short description an open-vocabulary detector might give (with paraphrase variety)."""
    noun = o.kind.replace("_", " ")
    if o.role == "part":
        owner = o.parent.split("/")[-1].rstrip("0123456789").rstrip("_").replace("_", " ") if o.parent else ""
        text = f"the {noun} of a {owner}" if rng.random() < 0.5 else f"a {owner}'s {noun}"
    else:
        words = [
            w
            for w in (
                size_word(o) if rng.random() < 0.5 else None,
                o.color,
                o.material if rng.random() < 0.4 else None,
            )
            if w
        ]
        article = "an" if (words[0] if words else noun)[0] in "aeiou" else "a"
        text = f"{article} {' '.join([*words, noun])}"
    state = [s for s in states if s != "held"]
    if state:
        text += f" ({', '.join(state)})"
    if "held" in states:
        text += ", in the gripper"
    return text
