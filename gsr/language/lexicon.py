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
from functools import lru_cache
from typing import Any

from gsr.categories import (
    COLOR_SYNONYMS,
    COLORS,
    ancestors,
    canonical,
    categories,
    category_of,
    get_category,
    is_category,
    is_part_category,
)
from gsr.errors import GSRError
from gsr.facts import node_affordances, node_colors
from gsr.language.words import DRAWER_WORDS, FILLER, FUNCTION_WORDS, POSITION_SYNONYMS, VERB_CLASSES, gerund
from gsr.resources import data_dir
from gsr.scene_graph import Node, SceneGraph

__all__ = [
    "DRAWER_WORDS",
    "FILLER",
    "FUNCTION_WORDS",
    "POSITION_SYNONYMS",
    "Entity",
    "Lexicon",
    "build_lexicon",
]

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
    own_words: frozenset[str] = frozenset()  # words of the node's own id, asset and material only
    extent: tuple[float, float, float] | None = None  # bounding-box size (x, y, z), when the graph has one
    broader: frozenset[str] = frozenset()  # vocabulary nouns that name it loosely ("cup" for a mug)


@dataclass(slots=True)
class Lexicon:
    """The graph's entities plus the phrase table (word sequence -> token class and value)."""

    entities: dict[str, Entity]
    phrases: dict[tuple[str, ...], tuple[str, str]] = field(default_factory=dict)
    max_phrase: int = 4

    def lookup(self, words: tuple[str, ...]) -> tuple[str, str] | None:
        """The (class, value) of a word sequence, or None."""
        return self.phrases.get(words)


@lru_cache(maxsize=1)
def vocabulary() -> dict[str, Any]:
    """The everyday vocabulary (data/language/vocabulary.yaml): verbs by class, dropped phrases, numbers,
    and nouns naming categories loosely (hypernyms and near-synonyms)."""
    import yaml

    path = data_dir() / "language" / "vocabulary.yaml"
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise GSRError(f"{path}: cannot read the grounder's vocabulary ({exc})") from None
    return {
        "verbs": {cls: [str(w) for w in words] for cls, words in (data.get("verbs") or {}).items()},
        "drop": [str(w) for w in data.get("drop") or ()],
        "numbers": {str(k): int(v) for k, v in (data.get("numbers") or {}).items()},
        "nouns": {str(k): frozenset(map(str, v)) for k, v in (data.get("nouns") or {}).items()},
        # read by the delivery benchmark's free-form request parser, not by the phrase table
        "spellings": {str(k): str(v) for k, v in (data.get("spellings") or {}).items()},
        "phrases": {str(k): str(v) for k, v in (data.get("phrases") or {}).items()},
        "synonyms": {str(k): tuple(map(str, v)) for k, v in (data.get("synonyms") or {}).items()},
        "shades": {str(k): str(v) for k, v in (data.get("shades") or {}).items()},
        "materials": {str(k): tuple(map(str, v)) for k, v in (data.get("materials") or {}).items()},
        "search_verbs": [str(w) for w in data.get("search_verbs") or ()],
        "participles": {str(k): str(v) for k, v in (data.get("participles") or {}).items()},
        "pronouns": {str(k): tuple(map(str, v)) for k, v in (data.get("pronouns") or {}).items()},
        "connectives": [str(w) for w in data.get("connectives") or ()],
        "place_nouns": [str(w) for w in data.get("place_nouns") or ()],
        "particles": [str(w) for w in data.get("particles") or ()],
        "appearance": [str(w) for w in data.get("appearance") or ()],
    }


def number_value(phrase: str) -> int | None:
    """The count a number word or numeral says ("two", "a couple of", "3"), or None."""
    if phrase.isdigit():
        return int(phrase)
    return vocabulary()["numbers"].get(phrase)


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
    material = node.attributes.get("material")
    if isinstance(material, str):  # "the wooden box", "the plastic crate"
        words |= _name_words(material)
    own = frozenset(words)
    raw = node.category.lower()
    unregistered = raw != cat and not is_category(raw)
    if unregistered:  # a category the registry does not know ("orange", "toy_car"): its own words name it
        words |= set(raw.split("_"))
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
    kinds = {cat, *ancestors(cat)} | ({raw} if unregistered else set())
    affs = node_affordances(node)
    broader = frozenset(w for w, names in vocabulary()["nouns"].items() if names & kinds)
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
        own_words=own,
        extent=_extent(node),
        broader=broader,
    )


def _extent(node: Node) -> tuple[float, float, float] | None:
    if node.bbox is None:
        return None
    lo, hi = node.bbox.min.as_tuple(), node.bbox.max.as_tuple()
    return (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])


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
    # categories the registry does not know, named by the graph's nodes ("the orange", "the toy car")
    raw_nouns = {c for e in entities.values() for c in e.kinds if not is_category(c)}
    for raw in raw_nouns:
        words = tuple(raw.split("_"))
        add(words, "NOUN", raw)
        add((*words[:-1], _plural(words[-1])), "NOUN", raw + "#pl")
    # colours

    for c in COLORS:
        add((c,), "COLOR", c, override=True)
    for syn, c in COLOR_SYNONYMS.items():
        add((syn,), "COLOR", c, override=True)
    # function words win over everything single-word except multi-word nouns ("orange juice" stays a noun)
    for phrase, cls in FUNCTION_WORDS.items():
        add(tuple(phrase.split()), cls, phrase, override=True)
    vocab = vocabulary()
    for cls, verbs in vocab["verbs"].items():  # everyday verbs: never over a noun, colour or function word
        for phrase in verbs:
            add(tuple(phrase.split()), cls, phrase)
    for phrase in vocab["drop"]:  # "one by one", "until none are left": said, but no part of the goal
        add(tuple(phrase.split()), "DROP", phrase, override=True)
    for phrase in vocab["numbers"]:
        add(tuple(phrase.split()), "NUM", phrase, override=True)
    for noun in vocab["nouns"]:  # loose names ("cup" for mugs): registered categories keep their words
        words = tuple(noun.split("_"))
        for phrase, value in ((words, noun), ((*words[:-1], _plural(words[-1])), noun + "#pl")):
            # over a name word ("wine" of wine_rack and wine_bottle), never over a noun or function word
            add(phrase, "NOUN", value, override=phrases.get(phrase, ("NAME",))[0] == "NAME")
    verb_phrases = [(p, c) for p, c in FUNCTION_WORDS.items()] + [
        (p, c) for c, ps in vocab["verbs"].items() for p in ps
    ]
    for phrase, cls in verb_phrases:  # "putting", "switching off": the verb's class
        words = phrase.split()
        if cls in VERB_CLASSES | {"FILL", "GIVE", "CONTINUE"} and words[0] not in ("opened", "turned"):
            add((gerund(words[0]), *words[1:]), cls, phrase)
    # a word that is both a colour and a noun of this scene ("the orange" fruit, "the orange cube")
    for raw in raw_nouns:
        if (raw,) in phrases and phrases[(raw,)][0] == "COLOR":
            phrases[(raw,)] = ("COLORNOUN", raw)
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
