"""The scene as prompt text: the compact graph text plus the facts it does not show.

Prompts (:mod:`gsr.reason.prompt`), the few-shot examples (:mod:`gsr.reason.examples`) and the
fine-tuning rows (:mod:`gsr.train.format`) all describe a scene this way, so a model sees one format.
"""

from __future__ import annotations

from gsr.facts import state_from_graph
from gsr.graph_text import to_prompt_text
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.semantics import compile_domain

#: Static predicates the scene text already says (colour, parts) or that only encode counting.
_SHOWN_STATIC = frozenset({"has_color", "part_of", "next"})
#: Fluents the scene text already says (relations and node states).
_SHOWN_FLUENTS = frozenset({"on", "in", "open", "turned_on", "holding"})


def scene_text(graph: SceneGraph, domain: Domain | None = None) -> str:
    """Compact scene text plus the facts it does not show (affordances, counters, hand) for ``domain``."""
    text = to_prompt_text(graph)
    if domain is None:
        return text
    state = state_from_graph(graph, domain)
    fluents = compile_domain(domain).fluents
    unary: dict[str, list[str]] = {}
    other: list[str] = []
    for atom in sorted(state.atoms, key=lambda a: (a.predicate, a.args)):
        if atom.predicate in (_SHOWN_FLUENTS if atom.predicate in fluents else _SHOWN_STATIC):
            continue
        if len(atom.args) == 1 and atom.predicate not in fluents:
            unary.setdefault(atom.predicate, []).append(atom.args[0])
        else:
            other.append(str(atom))
    lines = [text]
    if unary:
        lines.append("affords: " + "; ".join(f"{p}: {', '.join(objs)}" for p, objs in unary.items()))
    if other:
        lines.append("facts: " + " ".join(other))
    return "\n".join(lines)
