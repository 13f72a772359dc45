"""Delivery-instruction parser: a small lark grammar whose lexicon comes from the building graph.

The grammar fixes the sentence shapes ("fetch X from Y and deliver it to P", "bring X to P",
"P needs X. It is on Y", "can you bring P X"); the terminals (colours, object names, receptacles, rooms,
names, roles, garments, hair) are generated from the scene graph's node attributes, so the parser knows
exactly the words this building has. Earley with a dynamic lexer handles multi-word terminals.

This is the reader of the generated tasks' own language, and it answers a :class:`Reference` to ids of
the known building graph. PRS's free-form requests are a different input and a different answer, read by
:mod:`gsr.benchmarks.delivery.prs_parse`: open vocabulary, words classified on the grounder's lexicon,
the object phrase scored against the detector's type labels, the recipient by name or appearance words,
and a ``ParsedRequest`` of phrases the agent resolves later. A sentence this grammar reads is exact or
an error; a request that parser reads is a best reading. Neither replaces the other.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from gsr.benchmarks.delivery.reference import ObjectRef, PersonRef, Reference
from lark import Lark, Token, Tree
from lark.exceptions import LarkError

from gsr.errors import GSRError
from gsr.scene_graph import SceneGraph

_GRAMMAR = r"""
start: sentence "."?
?sentence: fetch | bring | need | can | "please" sentence
fetch: FETCH object_np source? "and" DELIVER "it" "to" person_np
bring: BRING object_np source? "to" person_np
can: "can" "you" BRING person_np object_np source? "?"
need: person_np NEEDS object_np (_SEP? "it" "is" source)?
object_np: ("the" | "a") COLOR? OBJECT
source: ("from" | "on" | "in" | "that" "is" "on" | "that" "is" "in") "the" RECEPTACLE ("in" room_ref)?
      | ("from" | "in") room_ref
room_ref: "the"? ROOM
person_np: NAME ("," person_desc)? person_loc? | person_desc person_loc?
person_desc: "the" (GENDER | ROLE) feature*
feature: "in" "the" COLOR GARMENT -> wears
       | "with" HAIR -> hair
       | "with" "glasses" -> glasses
person_loc: ","? ("who" "is")? "in" room_ref
FETCH: "fetch" | "get" | "grab" | "pick up"
DELIVER: "deliver" | "bring" | "take" | "hand" | "give"
BRING: "bring" | "take" | "carry"
NEEDS: "needs" | "wants" | "asked for"
_SEP: "," | "." | ";"
%ignore " "
"""


def _alternation(words: set[str]) -> str:
    if not words:
        return '"\\u0000never"'
    # longest first so "water bottle" wins over a shorter word that prefixes it
    return " | ".join(f'"{w}"' for w in sorted(words, key=lambda w: (-len(w), w)))


@dataclass(frozen=True)
class Lexicon:
    """Words of one building, each mapped to the id or value it denotes."""

    colors: frozenset[str]
    objects: dict[str, str]  # "water bottle" -> water_bottle
    receptacles: dict[str, str]  # "dining table" -> dining_table
    rooms: dict[str, str]  # "office 104" -> office_104
    names: dict[str, str]  # "imani" -> imani (person id)
    roles: frozenset[str]
    genders: frozenset[str]
    garments: frozenset[str]
    hair: frozenset[str]


def lexicon_from_graph(graph: SceneGraph) -> Lexicon:
    """The lexicon of a building graph (include people to learn names, roles and looks)."""
    colors, objects, receptacles, rooms, names = set(), {}, {}, {}, {}
    roles, genders, garments, hair = set(), set(), set(), set()
    contained = {e.source for e in graph.edges if e.relation in ("on", "in")}
    supports = {e.source: e.target for e in graph.edges if e.relation in ("on", "in")}
    room_ids = {n.id for n in graph.nodes if supports.get(n.id, "").startswith("floor_")}
    for n in graph.nodes:
        name = str(n.attributes.get("name", "")).lower()
        if n.category == "person":
            names[name] = n.id
            roles.add(str(n.attributes["role"]))
            genders.add(str(n.attributes["gender"]))
            garments.add(str(n.attributes["garment"]))
            colors.add(str(n.attributes["color"]))
            hair.add(str(n.attributes["hair"]))
        elif n.id in room_ids:
            rooms[name] = n.id
        elif "holds" in n.attributes:
            receptacles[name] = n.category
        elif n.color is not None and n.id in contained:
            objects[name] = n.category
            colors.add(n.color)
    return Lexicon(
        frozenset(colors), objects, receptacles, rooms, names,
        frozenset(roles), frozenset(genders), frozenset(garments), frozenset(hair),
    )  # fmt: skip


class InstructionParser:
    """Parses delivery instructions of one building into ``Reference`` objects."""

    def __init__(self, lexicon: Lexicon) -> None:
        """Compile the grammar with this lexicon's terminals."""
        self.lex = lexicon
        terminals = {
            "COLOR": set(lexicon.colors),
            "OBJECT": set(lexicon.objects),
            "RECEPTACLE": set(lexicon.receptacles),
            "ROOM": set(lexicon.rooms),
            "NAME": set(lexicon.names),
            "ROLE": set(lexicon.roles),
            "GENDER": set(lexicon.genders),
            "GARMENT": set(lexicon.garments),
            "HAIR": set(lexicon.hair),
        }
        grammar = _GRAMMAR + "".join(f"{k}: {_alternation(v)}\n" for k, v in terminals.items())
        self._lark = Lark(grammar, parser="earley", lexer="dynamic", ambiguity="resolve")

    def parse(self, text: str) -> Reference:
        """The reference an instruction makes; GSRError saying where parsing stopped if it cannot."""
        norm = re.sub(r"\s+", " ", text.strip().lower())
        norm = re.sub(r"\s*([,.;?])", r"\1", norm).replace(",", ", ").replace(".", ". ").strip()
        norm = re.sub(r"\s+", " ", norm).replace(" .", ".")
        try:
            tree = self._lark.parse(norm)
        except LarkError as exc:
            first = str(exc).strip().splitlines()[0]
            raise GSRError(f"cannot parse instruction {text!r}: {first}") from None
        return self._reference(tree)

    # ------------------------------------------------------------ tree -> Reference

    def _reference(self, tree: Tree) -> Reference:
        obj = next(tree.find_data("object_np"))
        sources = list(tree.find_data("source"))
        person = next(tree.find_data("person_np"))
        return Reference(
            object=self._object(obj, sources[0] if sources else None), person=self._person(person)
        )

    def _object(self, np_: Tree, source: Tree | None) -> ObjectRef:
        tok = _tokens(np_)
        receptacle = room = None
        if source is not None:
            st = _tokens(source)
            if "RECEPTACLE" in st:
                receptacle = self.lex.receptacles[st["RECEPTACLE"]]
            rooms = [t for t in source.scan_values(lambda v: isinstance(v, Token) and v.type == "ROOM")]
            if rooms:
                room = self.lex.rooms[str(rooms[0])]
        return ObjectRef(
            category=self.lex.objects[tok["OBJECT"]], color=tok.get("COLOR"), receptacle=receptacle, room=room
        )

    def _person(self, np_: Tree) -> PersonRef:
        fields: dict[str, object] = {}
        tok = _tokens(np_)
        if "NAME" in tok:
            fields["name"] = self.lex.names[tok["NAME"]]
        for desc in np_.find_data("person_desc"):
            dt = _tokens(desc)
            if "GENDER" in dt:
                fields["gender"] = dt["GENDER"]
            if "ROLE" in dt:
                fields["role"] = dt["ROLE"]
            for feat in desc.children:
                if not isinstance(feat, Tree):
                    continue
                ft = _tokens(feat)
                if feat.data == "wears":
                    fields["color"], fields["garment"] = ft["COLOR"], ft["GARMENT"]
                elif feat.data == "hair":
                    fields["hair"] = ft["HAIR"]
                elif feat.data == "glasses":
                    fields["glasses"] = True
        for loc in np_.find_data("person_loc"):
            rooms = list(loc.scan_values(lambda v: isinstance(v, Token) and v.type == "ROOM"))
            fields["room"] = self.lex.rooms[str(rooms[0])]
        return PersonRef(**fields)  # type: ignore[arg-type]


def _tokens(tree: Tree) -> dict[str, str]:
    """Direct-child tokens of a tree node by type (the first of each)."""
    out: dict[str, str] = {}
    for child in tree.children:
        if isinstance(child, Token) and child.type not in out:
            out[child.type] = str(child)
    return out
