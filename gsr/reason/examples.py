"""Few-shot examples: the ``Example`` type and the built-in one, its effects computed by the checker so it
always matches the domain."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from gsr.check import check_step
from gsr.diagnosis import Diagnosis
from gsr.facts import state_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.pddl.model import Atom, Domain
from gsr.reason.scene_text import scene_text
from gsr.reason.step_format import format_step
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.transition import StepRejected


@dataclass(frozen=True)
class Example:
    """A few-shot example: scene text, instruction, and either step lines or a goal formula."""

    scene: str
    instruction: str
    steps: tuple[str, ...] = ()
    goal: str | None = None

    def text(self, goal_mode: bool = False) -> str:
        """The example as prompt text."""
        answer = self.goal if goal_mode else "\n".join(self.steps)
        label = "Goal" if goal_mode else "Steps"
        return f"Scene:\n{self.scene}\nInstruction: {self.instruction}\n{label}:\n{answer}"


_EXAMPLE_SCENE = {
    "nodes": ["table", "green_box", "yellow_cube1", "small_cabinet", "small_cabinet/drawer_top(closed)"],
    "edges": ["green_box(on)table", "yellow_cube1(in)green_box", "small_cabinet(on)table"],
}
_EXAMPLE_INSTRUCTION = "put the yellow cube in the top drawer and close it"
_EXAMPLE_PLAN = (
    Step("open", ("small_cabinet/drawer_top",)),
    Step("pick", ("yellow_cube1", "green_box")),
    Step("place_in", ("yellow_cube1", "small_cabinet/drawer_top")),
    Step("close", ("small_cabinet/drawer_top",)),
)
_EXAMPLE_GOAL = "(and (in yellow_cube1 small_cabinet/drawer_top) (not (open small_cabinet/drawer_top)))"


def _atom_key(atom: Atom) -> tuple[str, tuple[str, ...]]:
    return atom.predicate, atom.args


def claimed_effects(diagnosis: Diagnosis, state: State) -> Step:
    """The checked step claiming exactly the change it makes in ``state`` (adds not yet true, deletes true)."""
    assert diagnosis.step is not None
    add = tuple(sorted((a for a in diagnosis.add if a not in state.atoms), key=_atom_key))
    delete = tuple(sorted((a for a in diagnosis.delete if a in state.atoms), key=_atom_key))
    return Step(diagnosis.step.action, diagnosis.step.args, add, delete)


def annotate_steps(domain: Domain, graph: SceneGraph, steps: Sequence[Step]) -> list[Step]:
    """The steps with their true effects as claims (the checker's transition); StepRejected if one is invalid."""
    state = state_from_graph(graph, domain)
    out = []
    for i, step in enumerate(steps, 1):
        diagnosis = check_step(domain, state, Step(step.action, step.args))
        if not diagnosis.ok:
            raise StepRejected(f"step {i}: {diagnosis}", diagnosis)
        out.append(claimed_effects(diagnosis, state))
        state = diagnosis.next_state
    return out


_CACHE: dict[int, tuple[Domain, Example]] = {}


def _example(domain: Domain) -> Example:
    graph = graph_from_gsr_bench(_EXAMPLE_SCENE)
    steps = annotate_steps(domain, graph, _EXAMPLE_PLAN)
    return Example(
        scene_text(graph, domain), _EXAMPLE_INSTRUCTION, tuple(format_step(s) for s in steps), _EXAMPLE_GOAL
    )


def builtin_example(domain: Domain) -> Example:
    """The built-in tabletop example (scene, instruction, checked steps with effects, goal)."""
    hit = _CACHE.get(id(domain))
    if hit is None or hit[0] is not domain:  # keyed by identity: Domain is mutable, not hashable
        hit = (domain, _example(domain))
        _CACHE[id(domain)] = hit
    return hit[1]


def default_examples(domain: Domain) -> tuple[Example, ...]:
    """The built-in few-shot example (tabletop domain only; none for other domains)."""
    if domain.name != "tabletop":
        return ()
    return (builtin_example(domain),)
