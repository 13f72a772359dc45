"""A symbolic state: the ground atoms that hold (closed world) and the typed objects."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from gsr.pddl.model import Atom, Domain, Problem


@dataclass(frozen=True)
class State:
    """Ground atoms that are true plus the objects (name -> type) they range over."""

    atoms: frozenset[Atom]
    objects: Mapping[str, str] = field(default_factory=dict)

    def __contains__(self, atom: object) -> bool:
        return atom in self.atoms

    def with_atoms(self, atoms: Iterable[Atom]) -> State:
        """The same objects with another set of true atoms."""
        return State(frozenset(atoms), self.objects)


def initial_state(domain: Domain, problem: Problem) -> State:
    """The problem's initial state; objects include the domain's constants."""
    return State(frozenset(problem.init), problem.all_objects(domain))
