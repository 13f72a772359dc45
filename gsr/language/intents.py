"""What a clause asks for: an Intent (verb, object references, destination) and its Dest."""

from __future__ import annotations

from dataclasses import dataclass

from gsr.language.refs import Ref


@dataclass(slots=True)
class Dest:
    """Where objects go: a node with a predicate, or a pairing rule."""

    kind: str  # "at" | "corresponding" | "different" | "by_color" | "any"
    predicate: str = "on"
    target: str | None = None
    category: str | None = None  # the slot category of a pairing rule ("box", "drawer")
    owner: tuple[str, ...] | None = None  # slots restricted to parts of these
    options: tuple[Dest, ...] = ()  # kind "any": "put the book into a drawer", any one of these


@dataclass(slots=True)
class Intent:
    """What one clause asks for."""

    verb: str
    objects: list[Ref]
    dest: Dest | None = None
    stated: bool = False  # an end state said as such ("make sure X is open", "leave X open"): never a means
