"""Reference resolution: a noun phrase of the parse tree -> the scene-graph nodes it denotes.

A noun phrase is read into a :class:`Description` (head categories, colours, position and name
words, relations to other phrases, quantifier). :func:`candidates` filters the graph's entities by it;
:class:`Ref` is the result: the node ids plus, for quantified phrases over static properties
(category and colour), the quantifier to emit (``forall ?x - cube``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from gsr.categories import get_category, is_a
from gsr.errors import GSRError
from gsr.language.errors import GroundingError
from gsr.language.lexicon import POSITION_SYNONYMS, Entity
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph

#: Graph relations that count as "next to" (either direction).
NEAR_RELATIONS = frozenset({"adjacent", "near", "left_of", "right_of", "front_of", "behind"})
#: Words of region names that are not about the reference object.
_REGION_FILLER = frozenset({"next", "to", "region", "between", "init", "side", "main", "table", "of"})


@dataclass(slots=True)
class Relation:
    """A restrictive relation of a noun phrase: ``on``, ``in``, ``from``, ``near``, ``between``, ``at``, ``side``."""

    kind: str
    targets: tuple[Ref | Place, ...]
    word: str = ""  # the side word for kind == "side"


@dataclass(slots=True)
class Description:
    """What a noun phrase says about its referent."""

    heads: list[tuple[str, bool]] = field(default_factory=list)  # (category, plural)
    entity: str | None = None  # a node id written in the instruction
    colors: list[str] = field(default_factory=list)
    positions: list[str] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    noun_mods: list[str] = field(default_factory=list)
    states: list[str] = field(default_factory=list)  # "open" / "closed"
    quant: str | None = None  # "all", "each", "both"
    owner: Ref | Place | None = None  # "of the cabinet"
    relations: list[Relation] = field(default_factory=list)
    same_color_as: Ref | None = None
    sizes: list[str] = field(default_factory=list)  # "small", "tall", ...
    head_words: dict[str, str] = field(default_factory=dict)  # category -> singular head as written ("crate")
    text: str = ""
    count: int | None = None  # "2 blue cubes", "a couple of mugs", "one cube": an exact count
    definite_count: bool = False  # "the two yellow cubes": all of them, and there must be that many
    indefinite: bool = False  # "a blue cube": any one of them
    excluded: set[str] = field(default_factory=set)  # "except the porcelain one"
    not_colors: list[str] = field(default_factory=list)  # "that is not yellow"
    other_than: set[str] | None = None  # "the other box": not one already mentioned
    definite: bool = False  # "the", "these", a possessive
    one_head: bool = False  # the head is "one" standing for an earlier head

    @property
    def plural(self) -> bool:
        """True for plural heads or a quantifier."""
        return self.quant is not None or any(p for _, p in self.heads)


@dataclass(slots=True)
class Ref:
    """A resolved reference: node ids, and the quantifiers that express it when it is quantified."""

    ids: tuple[str, ...]
    text: str
    plural: bool = False
    forall: tuple[tuple[str, tuple[str, ...]], ...] | None = None  # ((category, colours), ...)
    generic: bool = False  # the head was "items" / "objects" / "things"
    count: int | None = None  # exactly this many of ids (the others not) end at the destination
    distributive: bool = False  # "each red cube ... it": a singular pronoun may stand for each of them
    other: bool = False  # "the other box": as a relation target, any of ids but the object itself


@dataclass(slots=True)
class Place:
    """A place that is not a node ("the table center"): an owner and a position word."""

    owner: tuple[str, ...]
    position: str
    text: str


class Resolver:
    """Filters the graph's entities by descriptions."""

    def __init__(self, graph: SceneGraph, entities: dict[str, Entity], domain: Domain) -> None:
        self.graph = graph
        self.domain = domain
        self.entities = entities
        self.support: dict[str, tuple[str, str]] = {}
        self.near: set[tuple[str, str]] = set()
        for e in graph.edges:
            if e.relation in ("on", "in"):
                self.support[e.source] = (e.relation, e.target)
            elif e.relation in NEAR_RELATIONS:
                self.near.add((e.source, e.target))
                self.near.add((e.target, e.source))
        self.side_edges = {(e.source, e.relation, e.target) for e in graph.edges}

    # ------------------------------------------------------------ helpers

    def with_parts(self, ids: tuple[str, ...]) -> set[str]:
        """The ids plus every part below them."""
        out = set(ids)
        changed = True
        while changed:
            changed = False
            for e in self.entities.values():
                if e.parent in out and e.id not in out:
                    out.add(e.id)
                    changed = True
        return out

    def owner_words(self, ids: tuple[str, ...]) -> set[str]:
        """Name words of the owners (what region names mention: ``plate`` in ``plate_right_region``)."""
        out: set[str] = set()
        for i in ids:
            out |= set(self.entities[i].words)
        return out

    def regions(self, owner: tuple[str, ...], position: str, outside: bool = False) -> list[str]:
        """Region-like parts at ``position`` of the owner: its own parts, or a region named after it.

        ``outside`` ("to the right of the caddy", "behind the plate"): a place beside the owner, so
        the owner's own compartments (the caddy's right compartment) do not count.
        """
        pos = POSITION_SYNONYMS.get(position, position)
        if pos in ("middle", "center"):  # "the middle of the table" is its center region
            for word in (pos, "center" if pos == "middle" else "middle"):
                found = self._regions(owner, word, outside)
                if found:
                    return found
            return []
        return self._regions(owner, pos, outside)

    def _regions(self, owner: tuple[str, ...], pos: str, outside: bool) -> list[str]:
        owned = [
            e.id
            for e in self.entities.values()
            if e.parent in owner
            and pos in e.positions
            and e.category in (("region",) if outside else ("cabinet_top", "region", "compartment"))
        ]
        if owned:
            if pos == "top" and not outside:  # "the top of the shelf": its top side, not its top layer
                sides = [
                    i for i in owned if self.entities[i].category == "cabinet_top" or i.endswith("_side")
                ]
                owned = sides or owned
            return owned
        words = self.owner_words(owner) - _REGION_FILLER
        named = [
            e.id
            for e in self.entities.values()
            if e.category == "region"
            and pos in (e.words | e.positions)
            and words & (e.words - _REGION_FILLER - {pos})
        ]
        return named

    # ------------------------------------------------------------ matching

    def _head_matches(self, category: str) -> list[Entity]:
        if category == "*":  # a bare name word is the head: the name filter does the work
            return list(self.entities.values())
        strong = [e for e in self.entities.values() if category in e.kinds]
        if category == "thing":  # "items", "objects": what can be moved
            return [e for e in self.entities.values() if "movable" in e.affordances]
        if strong:
            return strong
        # a loose name from the vocabulary ("cups" for mugs, "drinks", "the container") when no object is
        # of the word's own category
        broader = [e for e in self.entities.values() if category in e.broader]
        if broader:
            return broader
        words = set(category.split("_"))
        return [e for e in self.entities.values() if words <= e.words]

    def _relation_holds(self, e: Entity, rel: Relation) -> bool:
        if rel.kind in ("on", "in", "from"):
            target = rel.targets[0]
            sup = self.support.get(e.id)
            if sup is None:
                return False
            if isinstance(target, Place):
                if target.position == "top" and rel.kind == "on":  # "on top of the other box"
                    return sup[1] in self.with_parts(target.owner)
                return sup[1] in self.with_parts(target.owner) and _region_position(target.position, e)
            if rel.kind != "from" and sup[0] != rel.kind and not self._loose_support(rel.kind, sup[1]):
                return False
            return sup[1] in self.with_parts(target.ids)
        if rel.kind == "at":
            target = rel.targets[0]
            sup = self.support.get(e.id)
            if isinstance(target, Place):
                return (
                    sup is not None
                    and sup[1] in self.with_parts(target.owner)
                    and _region_position(target.position, e)
                )
            return sup is not None and sup[1] in self.with_parts(target.ids)
        if rel.kind in ("under", "carries"):  # the target rests on (or in) this object
            target = rel.targets[0]
            ids = target.ids if isinstance(target, Ref) else target.owner
            return any(self.support.get(t, ("", ""))[1] in self.with_parts((e.id,)) for t in ids if t != e.id)
        if rel.kind == "near":
            return self._near(e, rel.targets[0])
        if rel.kind == "between":
            return all(self._near(e, t, between=True) for t in rel.targets)
        if rel.kind == "side":
            target = rel.targets[0]
            ids = target.ids if isinstance(target, Ref) else target.owner
            edge = {"left": "left_of", "right": "right_of", "front": "front_of", "back": "behind"}.get(
                rel.word
            )
            if edge and any((e.id, edge, t) in self.side_edges for t in ids):
                return True
            return rel.word in e.region_words and bool(self.owner_words(ids) & e.region_words)
        return False

    def _loose_support(self, kind: str, target: str) -> bool:
        """``on the drawer`` for an object in it, ``in the bowl`` for one on it: the word follows the target's kind."""
        aff = self.entities[target].affordances
        return (kind == "in" and "container" not in aff) or (kind == "on" and "supporter" not in aff)

    def _near(self, e: Entity, target: Ref | Place, between: bool = False) -> bool:
        ids = target.ids if isinstance(target, Ref) else target.owner
        if any((e.id, t) in self.near for t in ids):
            return True
        marker = "between" if between else "next"
        if marker not in e.region_words and not (between and "next" in e.region_words):
            return False
        return bool((self.owner_words(ids) - _REGION_FILLER) & (e.region_words - _REGION_FILLER))

    def candidates(self, d: Description, category: str) -> list[Entity]:
        """Entities matching the description with this head category."""
        found = self._head_matches(category)
        said = set(d.head_words.get(category, "").split())
        if said and said != set(category.split("_")):
            # a synonym that names a kind of its own ("kettle", "saucer" for pot, plate) does not fit an
            # object of another registered subkind (a moka pot) unless its own name says so
            found = [e for e in found if e.category == category or said <= e.own_words]
        if d.noun_mods:
            mod_words = {w for m in d.noun_mods for w in m.split("_")}
            with_mods = [
                e
                for e in found
                if mod_words <= e.words
                or any(m in e.kinds for m in d.noun_mods)
                # "the caddy compartment", "the cabinet drawer": the modifier names the owner
                or (e.parent is not None and all(m in self.entities[e.parent].kinds for m in d.noun_mods))
            ]
            if with_mods:
                found = with_mods
            elif any(self._head_matches(m) for m in d.noun_mods):
                # "the drawer handle"-style compounds read the other way round: the modifier is the head
                found = [
                    e
                    for m in d.noun_mods
                    for e in self._head_matches(m)
                    if set(category.split("_")) <= e.words
                ]
            # else: the modifier names nothing in the scene ("the cabinet shelf" where the only furniture
            # is a shelf): it describes the head's kind, so the head alone decides (ambiguity still errs)
        if d.colors:
            every = [e for e in found if set(d.colors) <= set(e.colors)]
            if not every and d.plural and len(d.colors) > 1:
                # "all the red and blue cubes": the red ones and the blue ones (no cube is both)
                every = [e for e in found if set(d.colors) & set(e.colors)]
                if not all(any(c in e.colors for e in every) for c in d.colors):
                    every = []
            found = every
        if d.not_colors:
            found = [e for e in found if not set(d.not_colors) & set(e.colors)]
        if d.excluded:  # "X except Y": Y must be among X ("the basket except the butter" is no reading)
            kept = [e for e in found if e.id not in d.excluded]
            found = kept if len(kept) < len(found) else []
        if d.other_than:
            others = [e for e in found if e.id not in d.other_than]
            found = others or found
        for p in d.positions:
            canon = POSITION_SYNONYMS.get(p, p)
            named = [e for e in found if canon in e.positions]
            if named or len(found) < 2:
                found = named
            else:
                found = self._extreme(found, canon) or self._between_ends(found, canon)
        for state in d.states:
            is_open = {n.id for n in self.graph.nodes if "open" in n.states}
            found = [
                e for e in found if "openable" in e.affordances and ((e.id in is_open) == (state == "open"))
            ]
        for w in d.names:
            found = [e for e in found if w in e.words or w in e.region_words]
        lid = category == "door" and not found  # no door nodes: a lid/door is its owner's open state
        if lid:
            found = [e for e in self.entities.values() if "openable" in e.affordances and not e.is_part]
        if d.owner is not None:
            owners = d.owner.ids if isinstance(d.owner, Ref) else d.owner.owner
            if lid:  # "the lid of the box", "the door of the microwave"
                found = [self.entities[o] for o in owners if "openable" in self.entities[o].affordances]
            else:
                found = self._owned(found, d.owner)
        if d.same_color_as is not None:
            ref_colors = {self._primary(i) for i in d.same_color_as.ids} - {None}
            found = [
                e for e in found if e.colors and e.colors[0] in ref_colors and e.id not in d.same_color_as.ids
            ]
        for rel in d.relations:
            own = _ids(tuple(t for t in rel.targets if not (isinstance(t, Ref) and t.other)))
            found = [e for e in found if e.id not in own and self._relation_holds(e, rel)]
        for word in d.sizes:
            found = self._sized(found, word, d)
        return found

    def _sized(self, found: list[Entity], word: str, d: Description) -> list[Entity]:
        """``the small box``: the candidate at that end of the size scale, by bounding boxes.

        One candidate: the adjective only describes it ("the short cabinet" in a scene with one cabinet).
        Several, with sizes in the graph: the ones at that end (smallest, largest, tallest, ...); several
        without sizes: an ambiguity error listing them.
        """
        if len(found) < 2:
            return found
        if any(e.extent is None for e in found):
            ids = ", ".join(e.id for e in found)
            raise GroundingError(
                f"{d.text!r} is ambiguous: the scene graph has no sizes to tell which of {ids} "
                f"{'are' if d.plural else 'is'} {word!r}",
                candidates=tuple(e.id for e in found),
                phrase=d.text,
            )
        measure, smallest = SIZE_SCALES[word]
        values = [(measure(e.extent), e) for e in found]  # type: ignore[arg-type]
        best = min(v for v, _ in values) if smallest else max(v for v, _ in values)
        return [e for v, e in values if v == best]

    def _extreme(self, found: list[Entity], side: str) -> list[Entity]:
        """``the left plate`` from relation edges: the candidate left of every other candidate."""
        pairs = {
            "left": ("left_of", "right_of"),
            "right": ("right_of", "left_of"),
            "front": ("front_of", "behind"),
            "back": ("behind", "front_of"),
        }.get(side)
        if pairs is None:
            return []
        rel, inverse = pairs
        return [
            e
            for e in found
            if all(
                (e.id, rel, o.id) in self.side_edges or (o.id, inverse, e.id) in self.side_edges
                for o in found
                if o.id != e.id
            )
        ]

    def _between_ends(self, found: list[Entity], position: str) -> list[Entity]:
        """``the book in the middle``: when the others are named as both ends of one axis (left and right),
        the ones named at neither end; nothing when no axis has both ends among the candidates."""
        if position not in ("middle", "center"):
            return []
        for ends in (("left", "right"), ("front", "back"), ("top", "bottom")):
            if all(any(end in e.positions for e in found) for end in ends):
                return [e for e in found if not (set(ends) & e.positions)]
        return []

    def _owned(self, found: list[Entity], owner: Ref | Place) -> list[Entity]:
        owners = owner.ids if isinstance(owner, Ref) else owner.owner
        owned = [e for e in found if e.parent in owners]
        if owned:
            return owned
        # "the top layer of the drawer": the owner phrase names a part, meaning the object that has it
        parents = {self.entities[i].parent for i in owners} - {None}
        return [e for e in found if e.parent in parents]

    def _primary(self, node_id: str) -> str | None:
        colors = self.entities[node_id].colors
        return colors[0] if colors else None

    # ------------------------------------------------------------ resolution

    def resolve(self, d: Description) -> Ref:
        """The reference a description makes; GroundingError when nothing or (singular) more than one matches."""
        if d.entity is not None:
            e = self.entities[d.entity]
            for rel in d.relations:  # "the milk called milk_1 inside the crate": the name must fit the rest
                if not self._relation_holds(e, rel):
                    raise GroundingError(f"no object in the scene matches {d.text!r}", phrase=d.text)
            wrong = [c for c, _ in d.heads if c not in ("*", "thing") and c not in e.kinds]
            if wrong:
                raise GroundingError(
                    f"{d.text!r}: {d.entity} is a {e.category}, not a {wrong[0]}",
                    candidates=(d.entity,),
                    phrase=d.text,
                )
            return Ref((d.entity,), d.text, plural=False)
        ids: list[str] = []
        forall: list[tuple[str, tuple[str, ...]]] = []
        for category, _plural in d.heads:
            found = self.candidates(d, category)
            if not found:
                raise GroundingError(
                    f"no object in the scene matches {d.text!r}",
                    phrase=d.text,
                    candidates=self.near_misses(category),
                )
            if not d.plural and len(found) > 1 and d.count is None:
                found = self.best_named(found, d, category)
            if not d.plural and len(found) > 1 and d.indefinite and d.count is None:
                d.count = 1  # "a blue cube": any one of them
            if not d.plural and len(found) > 1 and d.count is None:
                raise GroundingError(
                    f"{d.text!r} is ambiguous: it could be any of {', '.join(e.id for e in found)}",
                    candidates=tuple(e.id for e in found),
                    phrase=d.text,
                )
            ids.extend(e.id for e in found if e.id not in ids)
            if self._quantifiable(d, category) and all(category in e.kinds for e in found):
                forall.append((category, tuple(d.colors)))
        if d.quant == "both" and len(ids) != 2:
            raise GroundingError(
                f"{d.text!r} should name two objects, found {len(ids)}: {', '.join(ids)}",
                candidates=tuple(ids),
                phrase=d.text,
            )
        count = d.count
        if count is not None and (d.definite_count or count == len(ids)):
            if len(ids) != count:  # "the two yellow cubes": there must be two
                raise GroundingError(
                    f"{d.text!r} should name {count} object{'s' if count != 1 else ''}, found {len(ids)}: "
                    f"{', '.join(ids)}",
                    candidates=tuple(ids),
                    phrase=d.text,
                )
            count = None  # all of them
        elif count is not None and len(ids) < count:
            raise GroundingError(
                f"{d.text!r} asks for {count} but the scene has only {len(ids)}: {', '.join(ids)}",
                candidates=tuple(ids),
                phrase=d.text,
            )
        quantified = d.quant in ("all", "each") and len(forall) == len(d.heads) and count is None
        generic = any(c == "thing" for c, _ in d.heads)
        return Ref(
            tuple(ids),
            d.text,
            plural=d.plural or count is not None,
            forall=tuple(forall) if quantified else None,
            generic=generic,
            count=count,
            distributive=d.quant in ("all", "each"),
            other=d.other_than is not None,
        )

    def best_named(self, found: list[Entity], d: Description, category: str) -> list[Entity]:
        """Among several matches of a singular phrase, those the words fit most exactly, if that narrows them.

        In turn: exactly the named colours (``the white mug`` is the all-white one, not the
        white-and-yellow one); the category itself rather than a subcategory (``the box``, not the
        lidded box); the head noun as written in the node's own name or material (``the crate`` is
        ``crate_4``, not ``box_6``, though both are boxes; ``the plate`` is ``plate_2``, not
        ``saucer_1``), unless another candidate has the words beyond its category in its own name or
        material (``the glass cup`` also fits a cup made of glass). A preference applies only when it
        keeps some but not all candidates; when none narrows them, the phrase stays ambiguous.
        """
        exact = [e for e in found if d.colors and set(e.colors) == set(d.colors)]
        found = exact if 0 < len(exact) < len(found) else found
        same = [e for e in found if e.category == category]
        found = same if 0 < len(same) < len(found) else found
        said = set(d.head_words.get(category, "").split())
        if not said:
            return found
        named = [e for e in found if said <= e.own_words]
        # fits by its own words beyond its category: "the glass cup" also fits a cup made of glass, while
        # "the plate" does not fit a saucer better for being a plate by category
        also = [
            e
            for e in found
            if e not in named
            and (said - set(e.category.split("_"))) <= e.own_words - set(category.split("_"))
            and said - set(e.category.split("_"))
        ]
        fit = named if not also else named + also
        return fit if 0 < len(fit) < len(found) else found

    def _quantifiable(self, d: Description, category: str) -> bool:
        """A quantifier over static properties only (category, colour) becomes a PDDL forall."""
        return (
            not (
                d.positions or d.names or d.noun_mods or d.owner or d.relations or d.same_color_as or d.states
            )
            and not (d.excluded or d.not_colors or d.other_than or d.count is not None)
            and not (d.plural and len(d.colors) > 1)
            and category != "thing"
            and category in self.domain.types
        )

    def near_misses(self, category: str) -> tuple[str, ...]:
        """Objects of the category, else of its kind ("the cabinet" where there is only a shelf: furniture)."""
        same = tuple(e.id for e in self.entities.values() if is_a(e.category, category))
        if same or category in ("*", "thing"):
            return same
        try:
            parent = get_category(category).parent
        except GSRError:
            return ()
        if parent is None or parent in ("object", "thing", "entity"):
            return ()
        return tuple(e.id for e in self.entities.values() if not e.is_part and is_a(e.category, parent))


def _volume(x: tuple[float, float, float]) -> float:
    return x[0] * x[1] * x[2]


#: Size words: (the measure of a bounding-box extent, whether the word picks the smallest).
SIZE_SCALES = {
    **dict.fromkeys(("small", "smaller", "smallest", "little", "tiny"), (_volume, True)),
    **dict.fromkeys(("big", "bigger", "biggest", "large", "larger", "largest", "huge"), (_volume, False)),
    **dict.fromkeys(("tall", "taller", "tallest"), (lambda x: x[2], False)),
    **dict.fromkeys(("short", "shorter", "shortest"), (lambda x: x[2], True)),
    **dict.fromkeys(("long", "longer", "longest"), (lambda x: max(x[0], x[1]), False)),
    "wide": (lambda x: max(x[0], x[1]), False),
    "narrow": (lambda x: min(x[0], x[1]), True),
}


def _region_position(position: str, e: Entity) -> bool:
    """Whether the object's starting region names the position ("middle" and "center" alike)."""
    same = {"middle", "center"} if position in ("middle", "center") else {position}
    return bool(same & e.region_words)


def _ids(targets: tuple[Ref | Place, ...]) -> set[str]:
    out: set[str] = set()
    for t in targets:
        if isinstance(t, Ref):
            out |= set(t.ids)
    return out
