"""The ground steps applicable in a scene, with their true effects (for constrained decoding and hints)."""

from __future__ import annotations

import itertools
import math

from gsr.check import check_step
from gsr.facts import problem_from_graph, state_from_graph
from gsr.pddl.model import TRUE, Domain
from gsr.plan.grounding import ground_task
from gsr.reason.examples import claimed_effects
from gsr.scene_graph import SceneGraph
from gsr.semantics import compile_domain
from gsr.step import Step

#: Above this many typed argument combinations for one action, ground with the planner's grounder.
_MAX_COMBINATIONS = 200_000


def _calls(domain: Domain, graph: SceneGraph) -> list[tuple[str, tuple[str, ...]]]:
    """(action, args) applicable now: compiled preconditions over the typed argument lists."""
    cd = compile_domain(domain)
    state = state_from_graph(graph, domain)
    view = cd.view(state)
    calls: list[tuple[str, tuple[str, ...]]] = []
    for name, ca in cd.actions.items():
        lists = [view[1][slot] for slot in ca.param_slots]
        if math.prod(len(objs) for objs in lists) > _MAX_COMBINATIONS:
            # large scenes: relaxed-reachability grounding prunes the argument space first

            task = ground_task(domain, problem_from_graph(graph, TRUE, domain=domain))
            found = {(task.ops[i].name, task.ops[i].args) for i in task.applicable(task.init)}
            calls.extend(c for c in found if c[0] == name)
            continue
        calls.extend((name, args) for args in itertools.product(*lists) if ca.pre(*view, *args))
    return sorted(set(calls))


def applicable_steps(domain: Domain, graph: SceneGraph) -> list[Step]:
    """Every ground action applicable in ``graph``'s state, each claiming its true effects (sorted, unique)."""
    state = state_from_graph(graph, domain)
    out = []
    for name, args in _calls(domain, graph):
        diagnosis = check_step(domain, state, Step(name, args))
        if diagnosis.ok:  # the checker has the last word
            out.append(claimed_effects(diagnosis, state))
    return out
