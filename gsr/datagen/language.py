"""Instructions from templates: referring expressions for scene objects and paraphrased goal sentences.

Objects are named the way a person would: by type, adding colour and then material only when the
scene needs them to be unambiguous (``the bowl``, ``the blue bowl``, ``the blue ceramic bowl``), parts
through their owner (``the top drawer of the cabinet``). Each goal literal has several templates and
the conjunction has several connectives, so one goal yields many rephrasings (augmentation).
"""

from __future__ import annotations

import random

from gsr.datagen.goals import GoalLiteral
from gsr.datagen.scene import Scene, SceneObject

_IN = (
    "put {o} in {t}",
    "place {o} into {t}",
    "move {o} into {t}",
    "store {o} in {t}",
    "drop {o} into {t}",
    "make sure {o} ends up in {t}",
    "get {o} inside {t}",
)
_ON = (
    "put {o} on {t}",
    "place {o} on top of {t}",
    "set {o} on {t}",
    "move {o} onto {t}",
    "make sure {o} ends up on {t}",
    "rest {o} on {t}",
)
_OPEN = ("open {o}", "make sure {o} is open", "leave {o} open", "pull {o} open")
_CLOSE = ("close {o}", "shut {o}", "make sure {o} is closed", "leave {o} closed")
_ON_POWER = ("turn on {o}", "switch on {o}", "power up {o}", "make sure {o} is on")
_OFF_POWER = ("turn off {o}", "switch off {o}", "power down {o}", "make sure {o} is off")
_JOIN = (", then ", " and ", "; ", ", and ", ". Also, ")
_OPENERS = ("", "", "please ", "could you ", "I need you to ", "your task: ", "go ahead and ")


def _noun(o: SceneObject) -> str:
    return o.kind.replace("_", " ")


def describe(scene: Scene, oid: str) -> str:
    """The shortest unambiguous referring expression for an object in the scene."""
    o = scene.by_id[oid]
    if o.role == "table":
        return "the table"
    if o.role == "part":
        owner = scene.by_id[o.parent] if o.parent else None
        owner_text = describe(scene, owner.id) if owner else "it"
        return f"the {_noun(o)} of {owner_text}"
    same = [x for x in scene.objects if x.kind == o.kind and x.id != o.id]
    if not same:
        return f"the {_noun(o)}"
    if o.color and all(x.color != o.color for x in same):
        return f"the {o.color} {_noun(o)}"
    if o.material and all((x.color, x.material) != (o.color, o.material) for x in same):
        return f"the {o.color} {o.material} {_noun(o)}"
    return f"the {_noun(o)} called {o.id}"  # indistinguishable by looks: fall back to its name


def literal_sentence(scene: Scene, lit: GoalLiteral, rng: random.Random) -> str:
    """One templated clause for a goal literal."""
    o = describe(scene, lit.args[0])
    if lit.predicate in ("in", "on"):
        t = describe(scene, lit.args[1])
        return rng.choice(_IN if lit.predicate == "in" else _ON).format(o=o, t=t)
    if lit.predicate == "open":
        return rng.choice(_OPEN if lit.positive else _CLOSE).format(o=o)
    return rng.choice(_ON_POWER if lit.positive else _OFF_POWER).format(o=o)


def instruction(scene: Scene, goal: list[GoalLiteral] | tuple[GoalLiteral, ...], rng: random.Random) -> str:
    """A natural-language instruction for the goal, with random template, order and connectives."""
    clauses = [literal_sentence(scene, lit, rng) for lit in goal]
    if len(clauses) > 1 and rng.random() < 0.5:
        rng.shuffle(clauses)  # a conjunctive goal has no order; the text need not follow the plan
    text = clauses[0]
    for c in clauses[1:]:
        joiner = rng.choice(_JOIN)
        text += joiner + (c[0].upper() + c[1:] if joiner.endswith(". ") else c)
    text = rng.choice(_OPENERS) + text
    return text[0].upper() + text[1:] + "."
