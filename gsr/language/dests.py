"""Destinations of place/push clauses: ``in``/``on`` a node, beside a region, under, and the pairing rules.

A mixin of :class:`gsr.language.build.Interpreter` (it resolves the destination's noun phrase with the
interpreter's references and discourse), kept apart so each module has one job.
"""

from __future__ import annotations

from lark import Token, Tree

from gsr.language.errors import GroundingError
from gsr.language.intents import Dest
from gsr.language.parse import Tok
from gsr.language.refs import Place, Ref


class Destinations:
    """``dest`` and ``_at`` for the Interpreter (which supplies np, pronoun, target, place, _side, mentions)."""

    def dest(self, t: Tree, objects: list[Ref]) -> Dest:
        """The destination of a place/push clause."""
        own = tuple(i for r in objects for i in r.ids)
        kids = [c for c in t.children if isinstance(c, Tree)]
        kind = t.data
        if kind in ("dest_in", "dest_on", "dest_to"):
            prep = {"dest_in": "in", "dest_on": "on", "dest_to": "to"}[kind]
            try:
                ref = (
                    self.np(kids[-1], exclude=own, dest=True)
                    if kids[-1].data != "pronoun"
                    else self.pronoun(kids[-1], None, own)
                )
            except GroundingError as exc:
                words = tree_tokens(kids[-1])
                if not (
                    exc.candidates and "ambiguous" in exc.message and words[0].text in ("a", "an", "any")
                ):
                    raise
                # "put the book into a drawer": any one of them will do
                options = tuple(self._at(Ref((c,), exc.phrase or ""), prep) for c in exc.candidates)
                return Dest("any", options[0].predicate, options=options)
            if ref.count == 1 and len(ref.ids) > 1:  # "into a drawer": any one of them
                options = tuple(self._at(Ref((c,), ref.text), prep) for c in ref.ids)
                return Dest("any", options[0].predicate, options=options)
            if kids[-1].data == "pronoun":
                self.mentions.append(ref)
            return self._at(ref, {"dest_in": "in", "dest_on": "on", "dest_to": "to"}[kind])
        if kind == "dest_on_top":
            place = self.place(Tree("place_of", t.children[1:]), own)
            if isinstance(place, Place):
                raise GroundingError(f"there is no {place.text!r} in the scene", phrase=place.text)
            self.mentions.append(place)
            return self._at(place, "on")
        if kind == "dest_inside":
            for ref in reversed(self.mentions):
                if (
                    len(ref.ids) == 1
                    and ref.ids[0] not in own
                    and "container" in self.entities[ref.ids[0]].affordances
                ):
                    return Dest("at", "in", ref.ids[0])
            raise GroundingError(
                "'inside' does not refer to a container mentioned before it", phrase="inside"
            )
        if kind == "dest_under":
            # the tabletop domain has no "under": only a bottom part of the object (a shelf's lower
            # layer) can be the place, else the instruction cannot be stated as a goal
            text = " ".join(x.text for x in tree_tokens(kids[-1]))
            part = self._one_region(
                self.target(kids[-1], own),
                "bottom",
                text,
                f"bottom part of {text!r} to put things under it",
                "the tabletop domain has no 'under' predicate",
            )
            return self._at(Ref((part,), f"under {text}"), "in")
        if kind == "dest_near":
            text = " ".join(x.text for x in tree_tokens(kids[-1]))
            region = self._one_region(
                self.target(kids[-1]),
                "next",
                text,
                f"region next to {text!r}",
                "the tabletop domain has no 'next to' predicate, so such a goal needs a region part to put things on",
            )
            return Dest("at", "on", region)
        if kind == "dest_side":
            word, owner = self._side(kids[0], own)
            # "to the right of X" / "behind X" is beside X; "on the right side of X" may be a part of X
            outside = (
                kids[0].data == "side_behind"
                or any(token_class(x) == "TO" for x in t.children)
                or not any(token_class(x) in ("ON", "IN") for x in (*t.children, *kids[0].children))
            )
            text = " ".join(x.text for x in tree_tokens(kids[0]))
            region = self._one_region(
                owner,
                word,
                text,
                f"region {text!r}",
                "the tabletop domain states spatial goals only as regions (parts) an object is put on",
                outside=outside,
            )
            return Dest("at", "on", region)
        nominal = next(c for c in kids if c.data == "nominal")
        category = [
            token_value(x).value
            for x in nominal.children
            if isinstance(x, Token) and token_value(x).cls == "NOUN"
        ][-1]
        owner_tree = next((c for c in kids if c.data == "part_of"), None)
        owner = None
        if owner_tree is not None:
            o = self.target(owner_tree.children[-1])
            owner = o.ids if isinstance(o, Ref) else o.owner
        if kind == "dest_corresponding":
            return Dest("corresponding", "in", category=category)
        if kind == "dest_different":
            return Dest("different", "in", category=category, owner=owner)
        return Dest("by_color", "in", category=category, owner=owner)

    def _one_region(
        self, owner: Ref | Place, word: str, text: str, described: str, why: str, outside: bool = False
    ) -> str:
        """The one region part ``word`` of ``owner`` (a Ref or a Place); an error naming the candidates otherwise."""
        ids = owner.ids if isinstance(owner, Ref) else owner.owner
        found = self.resolver.regions(ids, word, outside=outside)
        if len(found) != 1:
            raise GroundingError(
                f"the scene graph has {'no' if not found else 'more than one'} {described}; {why}",
                candidates=tuple(found),
                phrase=text,
            )
        return found[0]

    def _at(self, ref: Ref, prep: str) -> Dest:
        if len(ref.ids) != 1:
            raise GroundingError(
                f"the destination {ref.text!r} must be one object, found {', '.join(ref.ids)}",
                candidates=ref.ids,
                phrase=ref.text,
            )
        target = ref.ids[0]
        aff = self.entities[target].affordances
        levels = [
            e.id
            for e in self.entities.values()
            if e.parent == target
            and e.positions & {"top", "middle", "bottom"}
            and e.affordances & {"container", "supporter"}
        ]
        if len(levels) > 1 and aff & {"container", "supporter"}:
            # "on the shelf" when the shelf has a top side and layers: which one is not said, never guess
            raise GroundingError(
                f"{ref.text!r} has several levels to put things {prep}: {', '.join(levels)}; say which "
                "(e.g. 'on top of', 'on the bottom layer of')",
                candidates=tuple(levels),
                phrase=ref.text,
            )
        order = {
            "in": ("container", "supporter"),
            "on": ("supporter", "stackable", "container"),  # blocks and cups stack on each other
            "to": ("container", "supporter"),
        }[prep]
        for a in order:
            if a in aff:
                return Dest("at", "in" if a == "container" else "on", target)
        for a in order:  # a cabinet: its one top surface or its one interior part
            parts = [e.id for e in self.entities.values() if e.parent == target and a in e.affordances]
            if len(parts) == 1:
                return Dest("at", "in" if a == "container" else "on", parts[0])
            if len(parts) > 1:
                raise GroundingError(
                    f"{ref.text!r} has several places to put things: {', '.join(parts)}",
                    candidates=tuple(parts),
                    phrase=ref.text,
                )
        raise GroundingError(
            f"nothing can be put {prep} {ref.text!r} ({target})", candidates=(target,), phrase=ref.text
        )


def token_value(x: Token | Tree) -> Tok:
    assert isinstance(x, Token)
    return x.value  # type: ignore[return-value]


def token_class(x: Token | Tree) -> str | None:
    return x.value.cls if isinstance(x, Token) else None  # type: ignore[union-attr]


def tree_tokens(t: Tree) -> list[Tok]:
    return [tok.value for tok in t.scan_values(lambda v: isinstance(v, Token))]  # type: ignore[misc]
