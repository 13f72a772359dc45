"""Steps, plans and goals: what a reasoner proposes and the checker validates."""

from __future__ import annotations

from dataclasses import dataclass, field

from gsr.pddl.model import TRUE, Atom, Formula


@dataclass(frozen=True, slots=True)
class Step:
    """One state transition: a ground action plus the effects the reasoner claims.

    ``add`` / ``delete`` are ``None`` when the reasoner made no claim (plain IPC plans);
    an empty tuple is a claim that nothing is added / deleted.
    """

    action: str
    args: tuple[str, ...] = ()
    add: tuple[Atom, ...] | None = None
    delete: tuple[Atom, ...] | None = None

    def __str__(self) -> str:
        return f"({' '.join((self.action, *self.args))})"

    @property
    def claims_effects(self) -> bool:
        """True when the step carries claimed effects to check."""
        return self.add is not None or self.delete is not None


@dataclass(frozen=True, slots=True)
class Plan:
    """An ordered list of steps."""

    steps: tuple[Step, ...] = ()

    def __len__(self) -> int:
        return len(self.steps)

    def __iter__(self):
        return iter(self.steps)


@dataclass(frozen=True, slots=True)
class Goal:
    """A PDDL goal formula over scene-graph entities, with the text it came from (if any)."""

    formula: Formula = TRUE
    text: str | None = None
    alternatives: tuple[Formula, ...] = field(default=())
