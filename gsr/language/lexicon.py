"""The lexicon: fixed function words plus the words a scene graph supplies (categories, colours, names).

Every node gets a description (:class:`Entity`): its category and the category's ancestors, its
colours, the words of its id and asset name (``akita``, ``wooden``, ``coffee``), the position words of
a drawer level (``top``/``high``/``upper`` for the highest drawer of a cabinet) and the words of the
region it stands on (``plate_left`` -> ``left``). Category words come from gsr.categories (names and
synonyms, multi-word ones such as ``moka pot`` or ``cream cheese box``) plus a few drawer words
(``layer``, ``level``, ``tier``) that name drawers in instructions.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from gsr.categories import ancestors, canonical, categories, category_of, get_category, is_part_category
from gsr.facts import node_affordances, node_colors
from gsr.scene_graph import Node, SceneGraph

#: Function words: word -> (token class, value). Multi-word entries are matched before single words.
FUNCTION_WORDS: dict[str, str] = {
    # verbs
    "put": "PLACE",
    "place": "PLACE",
    "move": "PLACE",
    "set": "PLACE",
    "drop": "PLACE",
    "insert": "PLACE",
    "transfer": "PLACE",
    "bring": "PLACE",
    "store": "PLACE",
    "stow": "PLACE",
    "load": "PLACE",
    "position": "PLACE",
    "relocate": "PLACE",
    "sort": "PLACE",
    "lay": "PLACE",
    "stack": "STACK",
    "empty": "EMPTY",
    "unload": "EMPTY",
    "unstack": "PLACE",
    "pick": "PICK",
    "grab": "PICK",
    "take": "PICK",
    "lift": "PICK",
    "grasp": "PICK",
    "get": "PICK",
    "fetch": "PICK",
    "retrieve": "PICK",
    "open": "OPEN",
    "opened": "OPEN",
    "closed": "CLOSED",
    "close": "CLOSE",
    "shut": "CLOSE",
    "turn": "TURN",
    "switch": "TURN",
    "activate": "ACTIVATE",
    "ignite": "ACTIVATE",
    "deactivate": "DEACTIVATE",
    "push": "PUSH",
    "slide": "PUSH",
    "shove": "PUSH",
    "press": "PRESS",
    # particles and prepositions
    "up": "UP",
    "out": "OUT",
    "on": "ON",
    "onto": "ON",
    "upon": "ON",
    "on to": "ON",
    "off": "OFF",
    "in": "IN",
    "into": "IN",
    "within": "IN",
    "in to": "IN",
    "inside of": "IN",
    "inside": "INSIDE",
    "to": "TO",
    "towards": "TO",
    "toward": "TO",
    "of": "OF",
    "from": "FROM",
    "out of": "FROM",
    "off of": "FROM",
    "between": "BETWEEN",
    "near": "NEAR",
    "beside": "NEAR",
    "next to": "NEAR",
    "close to": "NEAR",
    "adjacent to": "NEAR",
    "nearby": "NEAR",
    "by the side of": "NEAR",
    "at": "AT",
    "with": "WITH",
    "behind": "BEHIND",
    "under": "UNDER",
    "underneath": "UNDER",
    "beneath": "UNDER",
    "below": "UNDER",
    "per": "PER",
    "by": "BY",
    "as": "AS",
    # determiners, quantifiers, pronouns
    "the": "DET",
    "a": "DET",
    "an": "DET",
    "some": "DET",
    "their": "POSS",
    "its": "POSS",
    "all": "ALL",
    "every": "ALL",
    "each": "EACH",
    "both": "BOTH",
    "it": "IT",
    "them": "THEM",
    "this": "THIS",
    "that": "THAT",
    "which": "THAT",
    "who": "THAT",
    "is": "BE",
    "are": "BE",
    "has": "BE",
    "have": "BE",
    "sits": "BE",
    "sit": "BE",
    "lies": "BE",
    "one": "ONE",
    "ones": "ONE",
    # colour-matching words
    "same": "SAME",
    "color": "COLORWORD",
    "colour": "COLORWORD",
    "colors": "COLORWORD",
    "colours": "COLORWORD",
    "corresponding": "CORRESPONDING",
    "matching": "CORRESPONDING",
    "respective": "CORRESPONDING",
    "colored": "COLORED",
    "coloured": "COLORED",
    "color-coded": "COLORED",
    "different": "DIFFERENT",
    "separate": "DIFFERENT",
    "distinct": "DIFFERENT",
    # connectives
    "and": "AND",
    "then": "THEN",
    "also": "ALSO",
    "as well as": "AND",
    "and then": "THEN",
    "afterwards": "THEN",
    "after that": "THEN",
    ",": "COMMA",
    ";": "COMMA",
    ".": "PERIOD",
    # sides and positions
    "leftmost": "SIDE",
    "rightmost": "SIDE",
    "left": "SIDE",
    "right": "SIDE",
    "top": "POS",
    "bottom": "POS",
    "middle": "POS",
    "upper": "POS",
    "lower": "POS",
    "uppermost": "POS",
    "lowest": "POS",
    "highest": "POS",
    "topmost": "POS",
    "high": "POS",
    "low": "POS",
    "mid": "POS",
    "front": "POS",
    "back": "POS",
    "rear": "POS",
    "center": "POS",
    "centre": "POS",
    "side": "POS",
    "corner": "POS",
    "edge": "POS",
    "first": "POS",
    "second": "POS",
    "third": "POS",
}
#: Words dropped before parsing: politeness and adverbs that do not change the goal.
FILLER = frozenset(
    {
        "please",
        "carefully",
        "gently",
        "now",
        "too",
        "kindly",
        "robot",
        "then,",
        "again",
        "just",
        "quickly",
        "slowly",
        "you",
        "can",
        "could",
        "would",
        "will",
    }
)
#: Normalised position words: each maps to a canonical word matched against node descriptions.
POSITION_SYNONYMS: dict[str, str] = {
    "upper": "top",
    "uppermost": "top",
    "highest": "top",
    "topmost": "top",
    "high": "top",
    "third": "top",
    "lower": "bottom",
    "lowest": "bottom",
    "low": "bottom",
    "first": "bottom",
    "mid": "middle",
    "leftmost": "left",
    "rightmost": "right",
    "second": "middle",
    "centre": "center",
    "rear": "back",
}
#: Extra nouns for drawers: "the top layer of the cabinet", "different drawer layers".
DRAWER_WORDS = ("layer", "level", "tier", "drawer")
_LEVEL_NAMES = {0: ("bottom",), 1: ("middle",), 2: ("top",)}
_WORD = re.compile(r"[a-z]+")


@dataclass(frozen=True, slots=True)
class Entity:
    """What the grounder knows about one node."""

    id: str
    category: str
    kinds: frozenset[str]  # the category and its ancestors
    colors: tuple[str, ...]
    words: frozenset[str]  # name words: id, asset, category name and synonyms
    positions: frozenset[str]  # canonical position words (drawer level, region name)
    region_words: frozenset[str]
    parent: str | None
    affordances: frozenset[str]
    is_part: bool


@dataclass(slots=True)
class Lexicon:
    """The graph's entities plus the phrase table (word sequence -> token class and value)."""

    entities: dict[str, Entity]
    phrases: dict[tuple[str, ...], tuple[str, str]] = field(default_factory=dict)
    max_phrase: int = 4

    def lookup(self, words: tuple[str, ...]) -> tuple[str, str] | None:
        """The (class, value) of a word sequence, or None."""
        return self.phrases.get(words)


def _tokens(text: str) -> list[str]:
    return _WORD.findall(text.lower())


def _name_words(text: str) -> set[str]:
    return {w for w in _tokens(re.sub(r"\d+", " ", text))}


def _drawer_positions(node: Node, graph: SceneGraph) -> set[str]:
    """Canonical position words of a drawer: by its rank among its cabinet's drawers."""
    level = node.attributes.get("level")
    if node.parent is None or isinstance(level, bool) or not isinstance(level, int | float):
        return set()
    levels = sorted(
        {
            int(s.attributes["level"])
            for s in graph.parts(node.parent)
            if isinstance(s.attributes.get("level"), int | float)
            and not isinstance(s.attributes.get("level"), bool)
        }
    )
    rank = levels.index(int(level))
    out = set()
    if rank == 0:
        out.add("bottom")
    if rank == len(levels) - 1:
        out.add("top")
    if len(levels) == 3 and rank == 1:
        out.add("middle")
    return out


def describe(node: Node, graph: SceneGraph) -> Entity:
    """The entity description of a node."""
    cat = get_category(node.category).name
    words = _name_words(node.id.rsplit("/", 1)[-1])
    asset = node.attributes.get("asset")
    if isinstance(asset, str):
        words |= _name_words(asset)
    for c in (cat, *get_category(cat).synonyms):
        words |= set(c.split("_"))
    region = node.attributes.get("region")
    region_words = _name_words(region) if isinstance(region, str) else set()
    positions = {
        POSITION_SYNONYMS.get(w, w)
        for w in words | region_words
        if w in FUNCTION_WORDS and FUNCTION_WORDS[w] in ("POS", "SIDE")
    }
    if cat == "drawer":
        positions = (positions - {"top", "bottom", "middle"}) | _drawer_positions(node, graph)
        words |= set(DRAWER_WORDS)
    if cat == "cabinet_top":
        positions.add("top")
    kinds = {cat, *ancestors(cat)}
    affs = node_affordances(node)
    if "box" in kinds and "openable" in affs:  # GSR-Bench ``red_lid_box``: a box with a lid is a lidded box
        kinds.add("lidded_box")
        words |= {"lidded", "lid"}
    return Entity(
        id=node.id,
        category=cat,
        kinds=frozenset(kinds),
        colors=node_colors(node),
        words=frozenset(words),
        positions=frozenset(positions),
        region_words=frozenset(region_words),
        parent=node.parent,
        affordances=affs,
        is_part=node.parent is not None or is_part_category(cat),
    )


def build_lexicon(graph: SceneGraph) -> Lexicon:
    """The lexicon of a scene graph: entity descriptions and the phrase table."""
    entities = {n.id: describe(n, graph) for n in graph.nodes}
    phrases: dict[tuple[str, ...], tuple[str, str]] = {}

    def add(words: tuple[str, ...], cls: str, value: str, override: bool = False) -> None:
        if words and (override or words not in phrases):
            phrases[words] = (cls, value)

    # name words of the graph's nodes (modifiers such as "akita", "wooden", "coffee")
    for e in entities.values():
        for w in e.words | e.region_words:
            add((w,), "NAME", w)
    # category nouns (singular and plural), incl. multi-word ones
    for name, cat in categories().items():
        for phrase in (name, *cat.synonyms):
            words = tuple(phrase.split("_"))
            add(words, "NOUN", name, override=True)
            add((*words[:-1], _plural(words[-1])), "NOUN", name + "#pl", override=True)
    for w in ("layer", "level", "tier"):
        add((w,), "NOUN", "drawer", override=True)
        add((_plural(w),), "NOUN", "drawer#pl", override=True)
    for extra, cat in (
        ("cookies box", "cookie_box"),
        ("soup can", "alphabet_soup"),
        ("object", "thing"),
        ("objects", "thing#pl"),
        ("items", "thing#pl"),
        ("things", "thing#pl"),
        ("thing", "thing"),
        ("cookies boxes", "cookie_box#pl"),
    ):
        add(tuple(extra.split()), "NOUN", cat, override=True)
    # colours
    from gsr.categories import _COLOR_SYNONYMS, COLORS

    for c in COLORS:
        add((c,), "COLOR", c, override=True)
    for syn, c in _COLOR_SYNONYMS.items():
        add((syn,), "COLOR", c, override=True)
    # function words win over everything single-word except multi-word nouns ("orange juice" stays a noun)
    for phrase, cls in FUNCTION_WORDS.items():
        add(tuple(phrase.split()), cls, phrase, override=True)
    max_phrase = max(len(k) for k in phrases)
    return Lexicon(entities=entities, phrases=phrases, max_phrase=max_phrase)


def _plural(word: str) -> str:
    if word.endswith(("s", "x", "ch", "sh")):
        return word + "es"
    if word.endswith("y") and word[-2:-1] not in "aeiou":
        return word[:-1] + "ies"
    return word + "s"


def node_category_word(category: str) -> str | None:
    """The registered category a word denotes (synonyms resolved), or None."""
    return canonical(category)


def parse_node_name(name: str) -> tuple[str, dict[str, str | int]]:
    """Category and attributes of a raw name (re-exported for the lexer)."""
    return category_of(name)
