"""Intents -> one PDDL goal formula: placements, quantifiers, colour pairings, assignments, towers.

Two readings of the whole instruction are applied here: opening a container that a later clause puts
something into is the means, not a goal (unless the open state is said as an end state: "make sure
the drawer is open", "leave it open"), and picking up an object that a later clause places is only
a step. See docs/language.md for the encodings.
"""

from __future__ import annotations

import itertools

from gsr.language.errors import GroundingError
from gsr.language.intents import Dest, Intent
from gsr.language.refs import Ref, Resolver
from gsr.pddl.model import And, Atom, Domain, Equals, Forall, Formula, Imply, Not, Or, TypedVar

#: Most assignments a "different drawers" / "one colour per drawer" / tower goal may enumerate.
ASSIGNMENT_LIMIT = 512


def goal_formula(intents: list[Intent], resolver: Resolver, types: dict[str, str]) -> Formula:
    """The goal of an instruction's intents (see the module docstring for the two readings applied)."""
    placed_into = {i.dest.target for i in intents if i.verb == "place" and i.dest and i.dest.kind == "at"}
    placed_objs = {x for i in intents if i.verb == "place" for r in i.objects for x in r.ids}
    parts: list[Formula] = []
    for k, intent in enumerate(intents):
        later = intents[k + 1 :]
        later_into = {i.dest.target for i in later if i.verb == "place" and i.dest and i.dest.kind == "at"}
        ids = [x for r in intent.objects for x in r.ids]
        if intent.verb == "open":
            parts.extend(Atom("open", (x,)) for x in ids if intent.stated or x not in later_into)
        elif intent.verb == "close":
            parts.extend(Not(Atom("open", (x,))) for x in ids)
        elif intent.verb == "turn_on":
            parts.extend(Atom("turned_on", (x,)) for x in ids)
        elif intent.verb == "turn_off":
            parts.extend(Not(Atom("turned_on", (x,))) for x in ids)
        elif intent.verb == "press":
            parts.extend(_press(x, resolver) for x in ids)
        elif intent.verb == "pick":
            later_placed = {x for i in later if i.verb == "place" for r in i.objects for x in r.ids}
            parts.extend(Atom("holding", (x,)) for x in ids if x not in later_placed)
        elif intent.verb == "place":
            assert intent.dest is not None
            parts.extend(_place(intent, resolver, types))
        elif intent.verb == "tower":
            parts.append(_tower(ids, intent.dest.target if intent.dest else None))
    del placed_into, placed_objs
    flat: list[Formula] = []
    for p in parts:
        for q in p.parts if isinstance(p, And) else (p,):
            if q not in flat:
                flat.append(q)
    return And(tuple(flat))


def _tower(ids: list[str], base: str | None) -> Formula:
    """``stack the cups (on the green cup)``: one tower of all of them, in any order (an ``or`` of orders)."""
    count = 1
    for i in range(2, len(ids) + 1):
        count *= i
    if count > ASSIGNMENT_LIMIT:
        raise GroundingError(f"too many orders ({count}) to stack {len(ids)} objects", candidates=tuple(ids))
    options: list[Formula] = []
    for order in itertools.permutations(ids):
        below = [base, *order[:-1]] if base else list(order[:-1])
        above = order if base else order[1:]
        options.append(And(tuple(Atom("on", (a, b)) for a, b in zip(above, below, strict=True))))
    return options[0] if len(options) == 1 else Or(tuple(options))


def _press(x: str, resolver: Resolver) -> Formula:
    """Pressing toggles: the goal is the opposite of the owner's (or the button's) current state."""
    e = resolver.entities[x]
    owner = e.parent if e.parent and "switchable" in resolver.entities[e.parent].affordances else x
    node = resolver.graph.node(owner)
    atom = Atom("turned_on", (owner,))
    return Not(atom) if "on" in node.states else atom


def _place(intent: Intent, resolver: Resolver, types: dict[str, str]) -> list[Formula]:
    dest = intent.dest
    assert dest is not None
    if dest.kind == "any":  # "put the book into a drawer": all of them in any one
        objects = [x for r in intent.objects for x in r.ids]
        return [
            Or(tuple(And(tuple(Atom(o.predicate, (x, o.target)) for x in objects)) for o in dest.options))
        ]
    if dest.kind == "at":
        out: list[Formula] = []
        for ref in intent.objects:
            if ref.count is not None:  # "2 blue cubes": exactly that many of them end there
                ids = [x for x in ref.ids if x != dest.target]
                out.append(_exactly(ids, ref.count, dest))
                continue
            if ref.forall:
                out.extend(_forall(ref, dest, types, resolver.domain))
            else:
                ids = [x for x in ref.ids if x != dest.target]
                if (
                    ref.generic and dest.predicate == "in"
                ):  # "all items": a container never goes in a container
                    ids = [x for x in ids if "container" not in resolver.entities[x].affordances]
                out.extend(Atom(dest.predicate, (x, dest.target)) for x in ids)
        if not out:
            raise GroundingError(
                f"nothing to put at {dest.target}: the only object named is the destination itself"
            )
        return out
    objects = [x for r in intent.objects for x in r.ids]
    if dest.kind == "corresponding":
        return [_corresponding(x, dest, resolver) for x in objects]
    slots = _slots(dest, resolver)
    if dest.kind == "different":
        if len(slots) < len(objects):
            raise GroundingError(
                f"{len(objects)} objects need different {dest.category}s but there are only {len(slots)}: {', '.join(slots)}",
                candidates=tuple(slots),
            )
        return [_assignments(objects, slots, lambda x: x)]
    if _colored_slots(objects, slots, resolver):
        # "sort the cubes into the boxes by colour" when each colour has a box of its own colour: that box
        return [_corresponding(x, dest, resolver) for x in objects]
    colors: dict[str, str] = {}
    for x in objects:
        cs = resolver.entities[x].colors
        if not cs:
            raise GroundingError(f"{x} has no colour to sort it by", candidates=(x,))
        colors[x] = cs[0]
    groups = list(dict.fromkeys(colors.values()))
    if len(slots) < len(groups):
        raise GroundingError(
            f"{len(groups)} colours ({', '.join(groups)}) need one {dest.category} each but there are only "
            f"{len(slots)}: {', '.join(slots)}",
            candidates=tuple(slots),
        )
    return [_assignments(objects, slots, lambda x: colors[x], groups)]


def _forall(ref: Ref, dest: Dest, types: dict[str, str], domain: Domain) -> list[Formula]:
    out: list[Formula] = []
    assert ref.forall is not None and dest.target is not None
    for category, colors in ref.forall:
        var = "?x"
        conds: list[Formula] = [Atom("has_color", (var, c)) for c in colors]
        if types.get(dest.target) and domain.is_subtype(types[dest.target], (category,)):
            conds.append(Not(Equals(var, dest.target)))
        body: Formula = Atom(dest.predicate, (var, dest.target))
        if conds:
            body = Imply(conds[0] if len(conds) == 1 else And(tuple(conds)), body)
        out.append(Forall((TypedVar(var, (category,)),), body))
    return out


def _corresponding(x: str, dest: Dest, resolver: Resolver) -> Formula:
    cs = resolver.entities[x].colors
    if not cs:
        raise GroundingError(
            f"{x} has no colour, so it has no corresponding {dest.category}", candidates=(x,)
        )
    targets = [
        e.id
        for e in resolver.entities.values()
        if dest.category in e.kinds and e.colors and e.colors[0] == cs[0] and e.id != x
    ]
    if not targets:
        raise GroundingError(f"there is no {cs[0]} {dest.category} for {x}", candidates=(x,))
    atoms = [Atom("in", (x, t)) for t in targets]
    return atoms[0] if len(atoms) == 1 else Or(tuple(atoms))


def _slots(dest: Dest, resolver: Resolver) -> list[str]:
    slots = [
        e.id for e in resolver.entities.values() if dest.category in e.kinds and "container" in e.affordances
    ]
    if dest.owner is not None:
        slots = [s for s in slots if resolver.entities[s].parent in dest.owner]
    if not slots:
        raise GroundingError(f"there is no {dest.category} to put things in")
    return slots


def _assignments(objects: list[str], slots: list[str], key, groups: list[str] | None = None) -> Formula:
    """Or over injective maps from groups (default: the objects) to slots, each object in its group's slot."""
    groups = groups if groups is not None else list(objects)
    count = 1
    for i in range(len(groups)):
        count *= len(slots) - i
    if count > ASSIGNMENT_LIMIT:
        raise GroundingError(f"too many ways ({count}) to assign {len(groups)} groups to {len(slots)} places")
    options: list[Formula] = []
    for perm in itertools.permutations(slots, len(groups)):
        slot_of = dict(zip(groups, perm, strict=True))
        options.append(And(tuple(Atom("in", (x, slot_of[key(x)])) for x in objects)))
    return options[0] if len(options) == 1 else Or(tuple(options))


def _colored_slots(objects: list[str], slots: list[str], resolver: Resolver) -> bool:
    """Whether every object's colour is the colour of one of the slots (coloured boxes, not drawers)."""
    slot_colors = {resolver.entities[s].colors[0] for s in slots if resolver.entities[s].colors}
    obj_colors = {resolver.entities[x].colors[0] for x in objects if resolver.entities[x].colors}
    return bool(obj_colors) and obj_colors <= slot_colors


def _exactly(ids: list[str], n: int, dest: Dest) -> Formula:
    """Exactly ``n`` of the objects at the destination: an ``or`` over which ones (the others not there)."""
    options: list[Formula] = []
    for chosen in itertools.combinations(ids, n):
        options.append(
            And(
                tuple(
                    Atom(dest.predicate, (x, dest.target))
                    if x in chosen
                    else Not(Atom(dest.predicate, (x, dest.target)))
                    for x in ids
                )
            )
        )
        if len(options) > ASSIGNMENT_LIMIT:
            raise GroundingError(f"too many ways to choose {n} of {len(ids)} objects", candidates=tuple(ids))
    return options[0] if len(options) == 1 else Or(tuple(options))
