"""Applicable ground steps: exactly the steps the checker accepts, same answer on both enumeration paths."""

from __future__ import annotations

import itertools

import gsr.reason.applicable as applicable
from gsr.check import check_step
from gsr.facts import state_from_graph
from gsr.libero import libero_task
from gsr.pddl.bddl import parse_bddl
from gsr.step import Step


def test_matches_brute_force_and_planner_grounding(libero_dir, domain, monkeypatch):
    path = next((libero_dir / "libero_goal").glob("open_the_top_drawer*.bddl"))
    graph, _ = libero_task(parse_bddl(path.read_text(), str(path)))
    found = applicable.applicable_steps(domain, graph)
    state = state_from_graph(graph, domain)
    names = sorted(n.id for n in graph.nodes)  # every action parameter is a thing: constants never fit
    brute = set()
    for action in domain.actions.values():
        for args in itertools.product(names, repeat=len(action.params)):
            if check_step(domain, state, Step(action.name, args)).ok:
                brute.add((action.name, args))
    assert {(s.action, s.args) for s in found} == brute and brute
    assert all(check_step(domain, state, s).ok for s in found)  # the claimed effects are exact
    monkeypatch.setattr(applicable, "_MAX_COMBINATIONS", 0)  # force the planner-grounding path
    assert applicable.applicable_steps(domain, graph) == found
