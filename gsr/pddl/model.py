"""The PDDL data model: formulas, effects, actions, domains and problems.

Everything here is an immutable dataclass so that formulas can be hashed, compared
and shared between the checker, the planner and the writers. Names are stored in
lower case (PDDL is case-insensitive); variables keep their leading ``?``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

OBJECT = "object"


def is_variable(term: str) -> bool:
    """True for a PDDL variable such as ``?x``."""
    return term.startswith("?")


@dataclass(frozen=True, slots=True)
class TypedVar:
    """A typed parameter: ``?x - (either cube mug)`` has ``types == ("cube", "mug")``."""

    name: str
    types: tuple[str, ...] = (OBJECT,)


# ---------------------------------------------------------------- formulas


@dataclass(frozen=True, slots=True)
class Atom:
    """``(predicate arg ...)``; arguments are object names or variables."""

    predicate: str
    args: tuple[str, ...] = ()

    def __str__(self) -> str:
        return f"({' '.join((self.predicate, *self.args))})"


@dataclass(frozen=True, slots=True)
class Equals:
    """``(= a b)``."""

    left: str
    right: str


@dataclass(frozen=True, slots=True)
class Not:
    """``(not f)``."""

    formula: Formula


@dataclass(frozen=True, slots=True)
class And:
    """``(and f ...)``; the empty conjunction is true."""

    parts: tuple[Formula, ...]


@dataclass(frozen=True, slots=True)
class Or:
    """``(or f ...)``; the empty disjunction is false."""

    parts: tuple[Formula, ...]


@dataclass(frozen=True, slots=True)
class Imply:
    """``(imply a b)``."""

    condition: Formula
    then: Formula


@dataclass(frozen=True, slots=True)
class Exists:
    """``(exists (?x - t ...) f)``."""

    params: tuple[TypedVar, ...]
    body: Formula


@dataclass(frozen=True, slots=True)
class Forall:
    """``(forall (?x - t ...) f)``."""

    params: tuple[TypedVar, ...]
    body: Formula


@dataclass(frozen=True, slots=True)
class ForN:
    """BDDL ``(forn (n) (?x - t) f)``: at least ``count`` bindings of ``params`` satisfy ``body``."""

    count: int
    params: tuple[TypedVar, ...]
    body: Formula


@dataclass(frozen=True, slots=True)
class ForPairs:
    """BDDL ``(forpairs (?a - t1) (?b - t2) f)``: every ``first`` binding pairs with a distinct ``second`` one."""

    first: tuple[TypedVar, ...]
    second: tuple[TypedVar, ...]
    body: Formula


Formula = Atom | Equals | Not | And | Or | Imply | Exists | Forall | ForN | ForPairs

TRUE: Formula = And(())
FALSE: Formula = Or(())


# ----------------------------------------------------------------- effects


@dataclass(frozen=True, slots=True)
class Literal:
    """An effect literal: add ``atom`` or, when ``negated``, delete it."""

    atom: Atom
    negated: bool = False

    def __str__(self) -> str:
        return f"(not {self.atom})" if self.negated else str(self.atom)


@dataclass(frozen=True, slots=True)
class AndEffect:
    """``(and e ...)``."""

    parts: tuple[Effect, ...]


@dataclass(frozen=True, slots=True)
class When:
    """Conditional effect ``(when condition effect)``."""

    condition: Formula
    effect: Effect


@dataclass(frozen=True, slots=True)
class ForallEffect:
    """Universal effect ``(forall (?x - t) effect)``."""

    params: tuple[TypedVar, ...]
    effect: Effect


@dataclass(frozen=True, slots=True)
class Increase:
    """``(increase (total-cost) n)``: action costs (``:action-costs``)."""

    function: str
    args: tuple[str, ...]
    amount: float | str


Effect = Literal | AndEffect | When | ForallEffect | Increase

NO_EFFECT: Effect = AndEffect(())


# ------------------------------------------------------------ definitions


@dataclass(frozen=True, slots=True)
class Predicate:
    """A predicate declaration ``(name ?a - t ...)``."""

    name: str
    params: tuple[TypedVar, ...] = ()

    @property
    def arity(self) -> int:
        """Number of parameters."""
        return len(self.params)


@dataclass(frozen=True, slots=True)
class Action:
    """An action schema."""

    name: str
    params: tuple[TypedVar, ...]
    precondition: Formula = TRUE
    effect: Effect = NO_EFFECT


@dataclass(frozen=True, slots=True)
class Axiom:
    """A derived-predicate rule ``(:derived (name ?x - t ...) body)``.

    The head atom holds in a state when some binding of ``params`` (plus the body's own
    quantified variables) satisfies ``body``; several rules may derive the same predicate.
    Derived atoms are never changed by actions and never listed in ``:init``: they are the
    stratified least fixpoint of the rules over each state (see gsr.pddl.axioms).
    """

    name: str
    params: tuple[TypedVar, ...]
    body: Formula

    @property
    def head(self) -> Atom:
        """The derived atom over the rule's parameters."""
        return Atom(self.name, tuple(p.name for p in self.params))


@dataclass(slots=True)
class Domain:
    """A parsed PDDL domain.

    ``types`` maps each declared type to its parent types (``()`` only for ``object``; a type
    listed under several parents has all of them); ``constants`` maps constant names to their
    type; ``axioms`` are the derived-predicate rules (their predicates are in ``predicates``
    too).
    """

    name: str
    requirements: tuple[str, ...] = ()
    types: dict[str, tuple[str, ...]] = field(default_factory=lambda: {OBJECT: ()})
    constants: dict[str, str] = field(default_factory=dict)
    predicates: dict[str, Predicate] = field(default_factory=dict)
    functions: dict[str, Predicate] = field(default_factory=dict)
    actions: dict[str, Action] = field(default_factory=dict)
    axioms: list[Axiom] = field(default_factory=list)

    @property
    def derived(self) -> frozenset[str]:
        """Names of the derived predicates (heads of axioms)."""
        return frozenset(a.name for a in self.axioms)

    def supertypes(self, type_name: str) -> set[str]:
        """The type itself and all its ancestors (always including ``object``)."""
        seen: set[str] = set()
        stack = [type_name]
        while stack:
            t = stack.pop()
            if t in seen:
                continue
            seen.add(t)
            stack.extend(self.types.get(t, ()))
        seen.add(OBJECT)
        return seen

    def is_subtype(self, type_name: str, of: tuple[str, ...] | str) -> bool:
        """True when ``type_name`` is ``of`` or one of its descendants (``of`` may be an either-tuple)."""
        wanted = (of,) if isinstance(of, str) else of
        ancestors = self.supertypes(type_name)
        return any(w in ancestors for w in wanted)


@dataclass(slots=True)
class Problem:
    """A parsed PDDL problem. ``init`` holds the true atoms (closed world)."""

    name: str
    domain_name: str
    objects: dict[str, str] = field(default_factory=dict)
    init: frozenset[Atom] = frozenset()
    goal: Formula = TRUE
    requirements: tuple[str, ...] = ()
    init_numeric: dict[Atom, float] = field(default_factory=dict)
    metric: tuple[str, str] | None = None  # ("minimize", "total-cost")

    def all_objects(self, domain: Domain) -> dict[str, str]:
        """Objects of the problem together with the domain's constants."""
        merged = dict(domain.constants)
        merged.update(self.objects)
        return merged
