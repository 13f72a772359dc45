"""Goal sampling (task-oriented scene graphs, the GenManip approach) and the held-out compositions.

A goal is a conjunction of literals over the scene: an object ``in``/``on`` a target, a door or
drawer ``open`` or closed, an appliance ``turned_on`` or off. Literals are sampled from what the
scene affords and what is not already true, so every goal is a real change. Held-out compositions
(test split only): object-target pairs in :data:`HELDOUT_PAIRS`, the colours in
:data:`gsr.datagen.scene.HELDOUT_COLORS`, and plans longer than :data:`MAX_TRAIN_HORIZON`.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from gsr.datagen.scene import (
    HELDOUT_COLORS,
    Scene,
    SceneObject,
    fixed_surfaces,
    in_targets,
    on_targets,
    pair_key,
)
from gsr.pddl.model import And, Atom, Formula, Not

#: (object type, target type) pairs that appear only in the test split; parts count by category.
HELDOUT_PAIRS: frozenset[tuple[str, str]] = frozenset(
    {
        ("mug", "basket"),
        ("apple", "bowl"),
        ("ketchup", "drawer"),
        ("book", "tray"),
        ("banana", "plate"),
        ("cube", "lidded_box"),
        ("bottle", "box"),
        ("sponge", "microwave"),
        ("toy_car", "crate"),
        ("milk", "cabinet_interior"),
        ("cup", "caddy"),
        ("orange", "pan"),
        ("alphabet_soup", "basket"),
        ("marker", "caddy"),
        ("block", "bowl"),
        ("tennis_ball", "box"),
    }
)
#: Longest plan in train/val; the horizon test split holds only longer plans.
MAX_TRAIN_HORIZON = 8


@dataclass(frozen=True, slots=True)
class GoalLiteral:
    """One goal literal: ``(predicate args)``, or its negation when ``positive`` is False."""

    predicate: str
    args: tuple[str, ...]
    positive: bool = True

    @property
    def atom(self) -> Atom:
        """The literal's atom."""
        return Atom(self.predicate, self.args)

    def pddl(self) -> str:
        """``(in a b)`` or ``(not (open d))``."""
        text = f"({' '.join((self.predicate, *self.args))})"
        return text if self.positive else f"(not {text})"


def goal_formula(literals: list[GoalLiteral]) -> Formula:
    """The conjunction of the literals as a formula."""
    return And(tuple(lit.atom if lit.positive else Not(lit.atom) for lit in literals))


def goal_pddl(literals: list[GoalLiteral]) -> str:
    """The goal as PDDL text ``(and ...)``."""
    return f"(and {' '.join(lit.pddl() for lit in literals)})"


def _support(atoms: frozenset[Atom], oid: str) -> tuple[str, str] | None:
    for a in atoms:
        if a.predicate in ("on", "in") and a.args[0] == oid:
            return a.predicate, a.args[1]
    return None


def _move_options(
    scene: Scene, atoms: frozenset[Atom], obj: SceneObject, busy: set[str]
) -> list[tuple[str, SceneObject]]:
    """Targets ``obj`` could be moved to: not its current support, not itself, not a moving object."""
    current = _support(atoms, obj.id)
    if obj.role == "item":
        options = [("in", t) for t in in_targets(scene)] + [("on", t) for t in on_targets(scene)]
    elif obj.role == "supporter":  # plates and bowls go on fixed surfaces or into containers
        options = [("on", t) for t in fixed_surfaces(scene)] + [("in", t) for t in in_targets(scene)]
    else:  # containers never go into containers
        options = [("on", t) for t in fixed_surfaces(scene)]
    return [(r, t) for r, t in options if t.id != obj.id and t.id not in busy and (r, t.id) != current]


def _colored(scene: Scene, lit: GoalLiteral) -> bool:
    return any(scene.by_id[a].color in HELDOUT_COLORS for a in lit.args if a in scene.by_id)


def sample_goal(
    rng: random.Random, scene: Scene, atoms: frozenset[Atom], n_literals: int, tries: int = 20
) -> list[GoalLiteral] | None:
    """A goal of ``n_literals`` literals that are false in ``atoms``, respecting the scene's held-out tag.

    Returns None when the scene cannot host such a goal (the caller samples another scene or size).
    """
    for _ in range(tries):
        goal = _sample_once(rng, scene, atoms, n_literals)
        if goal is None:
            continue
        pairs = {pair_key(scene.by_id[g.args[0]], scene.by_id[g.args[1]]) for g in goal if len(g.args) == 2}
        if scene.heldout == "pair" and not pairs & HELDOUT_PAIRS:
            continue
        if scene.heldout != "pair" and pairs & HELDOUT_PAIRS:
            continue
        if scene.heldout == "color" and not any(_colored(scene, g) for g in goal):
            continue
        return goal
    return None


def _sample_once(
    rng: random.Random, scene: Scene, atoms: frozenset[Atom], n: int
) -> list[GoalLiteral] | None:
    movable = [o for o in scene.objects if o.movable]
    doors = [o for o in scene.objects if "openable" in o.affordances]
    powered = [o for o in scene.objects if "switchable" in o.affordances]
    if scene.heldout == "pair":
        # bias towards objects that have a held-out partner in the scene so pair goals are found
        kinds = {k for k, _ in HELDOUT_PAIRS}
        movable.sort(key=lambda o: o.kind not in kinds)
    goal: list[GoalLiteral] = []
    busy: set[str] = set()  # objects moved or used as targets: each appears in one relation
    attempts = 0
    while len(goal) < n and attempts < 4 * n + 4:
        attempts += 1
        kind = rng.random()
        if kind < 0.72 and movable:
            pool = [o for o in movable if o.id not in busy]
            if not pool:
                continue
            obj = pool[0] if scene.heldout == "pair" and not goal and rng.random() < 0.7 else rng.choice(pool)
            options = _move_options(scene, atoms, obj, busy)
            if scene.heldout == "pair" and not goal:
                preferred = [(r, t) for r, t in options if pair_key(obj, t) in HELDOUT_PAIRS]
                options = preferred or options
            if not options:
                continue
            rel, target = rng.choice(options)
            goal.append(GoalLiteral(rel, (obj.id, target.id)))
            busy.add(obj.id)
            if target.movable:
                busy.add(target.id)  # a movable host stays put while something lands on it
        elif kind < 0.88 and doors:
            d = rng.choice(doors)
            if d.id in busy:
                continue
            is_open = Atom("open", (d.id,)) in atoms
            goal.append(GoalLiteral("open", (d.id,), positive=not is_open))
            busy.add(d.id)
        elif powered:
            p = rng.choice(powered)
            if p.id in busy:
                continue
            on = Atom("turned_on", (p.id,)) in atoms
            goal.append(GoalLiteral("turned_on", (p.id,), positive=not on))
            busy.add(p.id)
    return goal if len(goal) == n else None
