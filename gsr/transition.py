"""Applying validated steps to scene graphs: graph + step -> next graph (via the checker)."""

from __future__ import annotations

from collections.abc import Iterable

from gsr.check import check_step
from gsr.errors import GSRError
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import Domain
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.semantics import apply
from gsr.step import Step


class StepRejected(GSRError):
    """A step the checker rejects; ``diagnosis`` holds the checker's full report."""

    def __init__(self, message: str, diagnosis: object) -> None:
        super().__init__(message)
        self.diagnosis = diagnosis


def _domain(domain: Domain | None) -> Domain:
    if domain is not None:
        return domain

    return load_builtin_domain("tabletop")


def apply_step(graph: SceneGraph, step: Step, domain: Domain | None = None) -> SceneGraph:
    """The graph after ``step``; raises :class:`StepRejected` (a GSRError) with the diagnosis when invalid."""
    domain = _domain(domain)
    state = state_from_graph(graph, domain)
    diagnosis = check_step(domain, state, step)
    if not diagnosis.ok:
        raise StepRejected(str(diagnosis), diagnosis)
    nxt = diagnosis.next_state
    if nxt is None:  # an ok diagnosis always carries its transition; guard against a bare one
        nxt = apply(domain, state, step.action, step.args)
    return graph_with_state(graph, nxt)


def apply_steps(graph: SceneGraph, steps: Iterable[Step], domain: Domain | None = None) -> list[SceneGraph]:
    """The graphs after each step in turn (not including ``graph``); stops with StepRejected at a bad step."""
    domain = _domain(domain)
    out: list[SceneGraph] = []
    for i, step in enumerate(steps, 1):
        try:
            graph = apply_step(graph, step, domain)
        except StepRejected as exc:
            raise StepRejected(f"step {i}: {exc}", exc.diagnosis) from None
        out.append(graph)
    return out
