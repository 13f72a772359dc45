"""Compiled per-schema effect grounding: one generated Python function per action schema that
grounds a fired action's effects and queues its new add effects for the fixpoint.

``ground_effects`` + ``new_adds`` (gsr.plan.grounding.effects) interpret a schema's effect groups
for every fired action: a shape test per group, a ``map(binding.get, ...)`` per effect atom, and a
second pass over all blocks for the adds not reached yet. Most tabletop effects are unconditional
literals over the action's parameters (pick's ``(holding ?o)``, ``(not (on ?o ?from))``); here those
are compiled once per domain into inline key tuples, one block per group exactly as
``_unconditional`` builds it, each add tested against the reached keys right there. The other groups
(effect variables, conditions) go through ``group_effects`` and ``new_adds`` as before, in the same
order, so the blocks, the deferred groups and the queued adds are identical, in the same order
(tests compare against ``GSR_GROUND_COMPILED=0``).
"""

from __future__ import annotations

from collections.abc import Callable

from gsr.plan.grounding.effects import EMPTY, EffectGroup, group_effects, new_adds, unconditional
from gsr.plan.grounding.normalize import Schema

# fire(v, simplify, reached, deferred, memo, pending): v.effects set, new adds queued in pending.
Fire = Callable[..., None]


def compile_effects(schema: Schema, groups: list[EffectGroup]) -> Fire:
    """The effect grounding of one schema's fired actions (see module docstring)."""
    names = [p.name for p in schema.all_params]
    slots = {n: f"v{k}" for k, n in enumerate(names)}
    used: set[str] = set()
    body: list[str] = []
    consts: dict[str, object] = {}
    nkeys = 0

    def term(x: str) -> str:
        # binding.get(x, x): a parameter's value, anything else (a constant) as written
        if x in slots:
            used.add(x)
            return slots[x]
        return repr(x)

    for k, group in enumerate(groups):
        if not unconditional(group):
            consts[f"G{k}"] = group
            body.append("    start = len(effects)")
            body.append(f"    group_effects(v, G{k}, simplify, reached, deferred, memo)")
            body.append("    if len(effects) > start:")
            body.append("        new_adds(effects[start:], reached, pending, memo)")
            continue
        lits = []
        adds = []
        for atom, is_del in group[4]:
            args = [term(a) for a in atom.args]
            key = f"k{nkeys}"
            nkeys += 1
            inner = "(" + ", ".join(args) + ("," if len(args) == 1 else "") + ")"
            body.append(f"    {key} = ({atom.predicate!r}, {inner})")
            lits.append(f"({key}, {is_del!r})")
            if not is_del:
                adds.append(key)
        ground = "(" + ", ".join(lits) + ("," if len(lits) == 1 else "") + ")"
        body.append(f"    effects.append((EMPTY, [(EMPTY, {ground})]))")
        for key in adds:  # new_adds of an unconditional block: no condition atoms
            body.append(f"    if {key} not in reached:")
            body.append(f"        pending.append(((), {key}))")
    head = [f"    {slots[n]} = b[{n!r}]" for n in names if n in used]
    src = "\n".join(
        [
            "def fire(v, simplify, reached, deferred, memo, pending):",
            "    b = v.binding",
            "    effects = v.effects = []",
            *head,
            *body,
            "",
        ]
    )
    env: dict[str, object] = {
        "EMPTY": EMPTY,
        "group_effects": group_effects,
        "new_adds": new_adds,
        **consts,
    }
    exec(compile(src, f"<compiled effects of {schema.name}>", "exec"), env)
    fire = env["fire"]
    fire.source = src  # type: ignore[attr-defined]
    return fire  # type: ignore[return-value]
