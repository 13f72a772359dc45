"""The object category registry: taxonomy, affordances, synonyms, colours and name parsing.

Scene-graph nodes carry a base ``category`` (``cube``, ``drawer``, ``bowl`` ...). The registry
says where a category sits in the taxonomy (which becomes the PDDL type hierarchy of the
tabletop domain), which affordances it has (static facts such as ``(container x)``) and which
words mean it. :func:`category_of` turns raw names (``red_cube1``, ``akita_black_bowl_1``,
``short_cabinet/drawer_low``) into a category plus attributes and never fails: unknown names
fall back to ``thing`` (movable).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache
from types import MappingProxyType

#: Affordances a category may have; each is a static predicate of the tabletop domain.
AFFORDANCES: tuple[str, ...] = (
    "movable",  # can be picked up
    "container",  # things go IN it (boxes, drawers, basket, compartments, microwave)
    "supporter",  # things go ON it (table, plate, bowl, stove, rack, box tops, cabinet top)
    "openable",  # has an open/closed state (drawer, lidded box, microwave, door)
    "switchable",  # has an on/off state (stove, lamp, tap)
    "pressable",  # a button or switch that toggles itself and its owner
    "pushable",  # can be slid along a surface
    "stackable",  # RLBench-style stacking (blocks, cups)
    "counted",  # counts toward a container's 10-cube capacity (GSR-Bench cubes)
)

#: The colour palette: colour words recognised in names; PDDL ``color`` constants.
COLORS: tuple[str, ...] = (
    "red",
    "blue",
    "yellow",
    "green",
    "black",
    "white",
    "orange",
    "purple",
    "pink",
    "brown",
    "grey",
    "gold",
    "silver",
    "cyan",
)
COLOR_SYNONYMS = {"gray": "grey", "golden": "gold", "violet": "purple"}
MATERIALS = frozenset({"wooden", "wood", "porcelain", "glass", "metal", "plastic", "ceramic", "paper"})
SIZES = frozenset({"short", "tall", "small", "large", "big", "little", "flat"})
#: Position words that give a drawer's ``level`` (0 = bottom).
LEVEL_WORDS = MappingProxyType(
    {"low": 0, "bottom": 0, "lower": 0, "middle": 1, "mid": 1, "high": 2, "top": 2, "upper": 2}
)


@dataclass(frozen=True, slots=True)
class Category:
    """A base category: its parent in the taxonomy, affordances and synonyms."""

    name: str
    parent: str
    affordances: frozenset[str] = frozenset()
    synonyms: tuple[str, ...] = ()
    part: bool = False  # an articulated part or region of another object (never movable)


# Grouping types: taxonomy only, no affordances of their own.
_GROUPS = ("furniture", "appliance", "part", "receptacle", "tableware", "cookware", "food", "toy")

M, C, S, OP, W, P, U, K, N = (  # short names keep the table below readable
    "movable",
    "container",
    "supporter",
    "openable",
    "switchable",
    "pressable",
    "pushable",
    "stackable",
    "counted",
)

# name: (parent, affordances, synonyms, is_part)
_TABLE: dict[str, tuple[str, tuple[str, ...], tuple[str, ...], bool]] = {
    "thing": ("object", (M,), ("object", "item"), False),
    # furniture and fixtures
    "table": ("furniture", (S,), ("desk", "counter", "worktop"), False),
    "floor": ("furniture", (S,), ("ground",), False),
    "cabinet": ("furniture", (), ("cupboard", "dresser", "chest_of_drawers"), False),
    "shelf": ("furniture", (S,), ("bookshelf", "shelving", "two_layer_shelf"), False),
    "rack": ("furniture", (S,), ("wine_rack", "dish_rack", "drainer", "bowl_drainer"), False),
    # appliances
    "microwave": ("appliance", (C, OP, W), ("microwave_oven",), False),
    "stove": ("appliance", (S, W), ("cooktop", "hob", "flat_stove", "range"), False),
    "lamp": ("appliance", (W,), ("light", "desk_lamp"), False),
    "tap": ("appliance", (W,), ("faucet",), False),
    # parts and regions
    "drawer": ("part", (C, OP), (), True),
    "cabinet_top": ("part", (S,), ("top_side", "cabinet_surface"), True),
    "cabinet_interior": ("part", (C,), ("cabinet_inside",), True),
    "compartment": ("part", (C,), ("section", "slot"), True),
    "burner": ("part", (S, W), ("cook_region", "hotplate"), True),
    "door": ("part", (OP,), ("lid",), True),
    "button": ("part", (P,), ("push_button",), True),
    "switch": ("part", (P,), ("toggle", "light_switch"), True),
    "region": ("part", (S,), ("area", "zone", "spot"), True),
    # receptacles
    "box": ("receptacle", (M, C, S, U), ("crate", "bin_box"), False),
    "lidded_box": ("box", (M, C, S, OP, U), ("box_with_lid", "lid_box"), False),
    "basket": ("receptacle", (M, C, U), ("bin", "hamper"), False),
    "tray": ("receptacle", (M, C, U), ("wooden_tray",), False),
    "caddy": ("receptacle", (M, C, U), ("desk_caddy", "organizer"), False),
    # tableware
    "plate": ("tableware", (M, S, U), ("dish", "saucer"), False),
    "bowl": ("tableware", (M, S, U), (), False),
    "mug": ("tableware", (M, U), ("coffee_mug", "tea_mug"), False),
    "cup": ("tableware", (M, K), ("glass_cup", "tumbler"), False),
    "ramekin": ("tableware", (M, S, U), (), False),
    # cookware
    "pot": ("cookware", (M,), ("saucepan", "kettle", "teapot"), False),
    "moka_pot": ("pot", (M,), ("espresso_maker", "coffee_pot"), False),
    "pan": ("cookware", (M, S), ("frypan", "frying_pan", "skillet"), False),
    # toys and blocks
    "cube": ("toy", (M, U, N), (), False),
    "block": ("toy", (M, U, K), ("brick",), False),
    # books and bottles
    "book": ("thing", (M, U), ("notebook",), False),
    "bottle": ("thing", (M,), (), False),
    "wine_bottle": ("bottle", (M,), (), False),
    # food packages
    "milk": ("food", (M,), ("milk_carton",), False),
    "popcorn": ("food", (M,), (), False),
    "ketchup": ("food", (M,), (), False),
    "alphabet_soup": ("food", (M,), ("soup", "soup_can"), False),
    "cream_cheese": ("food", (M,), ("cream_cheese_box",), False),
    "butter": ("food", (M,), (), False),
    "bbq_sauce": ("food", (M,), ("barbecue_sauce",), False),
    "tomato_sauce": ("food", (M,), (), False),
    "orange_juice": ("food", (M,), ("juice",), False),
    "salad_dressing": ("food", (M,), ("dressing",), False),
    "chocolate_pudding": ("food", (M,), ("pudding",), False),
    "macaroni_and_cheese": ("food", (M,), ("mac_and_cheese",), False),
    "cookie_box": ("food", (M, S, U), ("cookies", "cookie"), False),
}

#: Whole asset names (after stripping instance numbers) that need more than suffix rules.
ASSETS: MappingProxyType[str, tuple[str, dict[str, str | int]]] = MappingProxyType(
    {
        "akita_black_bowl": ("bowl", {"color": "black"}),
        "porcelain_mug": ("mug", {"color": "white", "material": "porcelain"}),
        "white_yellow_mug": ("mug", {"color": "white", "secondary_color": "yellow"}),
        "red_coffee_mug": ("mug", {"color": "red"}),
        "glazed_rim_porcelain_ramekin": ("ramekin", {"material": "porcelain"}),
        "chefmate_8_frypan": ("pan", {}),
        "wooden_two_layer_shelf": ("shelf", {"material": "wooden"}),
        "new_salad_dressing": ("salad_dressing", {}),
        "main_table": ("table", {}),
        "kitchen_table": ("table", {}),
        "living_room_table": ("table", {}),
        "study_table": ("table", {}),
    }
)

_REGISTRY: MappingProxyType[str, Category] = MappingProxyType(
    {
        **{g: Category(g, "thing") for g in _GROUPS},
        **{
            name: Category(name, parent, frozenset(aff), syns, part)
            for name, (parent, aff, syns, part) in _TABLE.items()
        },
    }
)

_SYNONYMS: MappingProxyType[str, str] = MappingProxyType(
    {s: c.name for c in _REGISTRY.values() for s in c.synonyms}
)

_NUMERIC_SUFFIX = re.compile(r"(?:[_\-.]?\d+)+$")


@dataclass(frozen=True, slots=True)
class ParsedName:
    """The result of parsing a raw name: base category and attributes."""

    category: str
    attributes: dict[str, str | int] = field(default_factory=dict)


def categories() -> MappingProxyType[str, Category]:
    """All registered categories by name (including the grouping types)."""
    return _REGISTRY


def get_category(name: str) -> Category:
    """The registered category ``name`` (synonyms resolved); ``thing`` when unknown."""
    key = name.lower()
    key = _SYNONYMS.get(key, key)
    return _REGISTRY.get(key, _REGISTRY["thing"])


def is_category(name: str) -> bool:
    """True when ``name`` is a registered category or one of its synonyms."""
    key = name.lower()
    return key in _REGISTRY or key in _SYNONYMS


def synonyms(category: str) -> tuple[str, ...]:
    """Words that mean ``category`` (not including the name itself)."""
    return get_category(category).synonyms


def canonical(word: str) -> str | None:
    """The category a word (a category name or synonym) denotes, or None."""
    key = word.lower()
    if key in _REGISTRY:
        return key
    return _SYNONYMS.get(key)


def ancestors(category: str) -> tuple[str, ...]:
    """The category's parents up to ``thing`` (nearest first), excluding itself."""
    out: list[str] = []
    cat = get_category(category)
    while cat.name != "thing":
        cat = _REGISTRY.get(cat.parent, _REGISTRY["thing"])
        out.append(cat.name)
    return tuple(out)


def is_a(category: str, ancestor: str) -> bool:
    """True when ``category`` is ``ancestor`` or below it in the taxonomy."""
    c = get_category(category).name
    return c == ancestor or ancestor in ancestors(c)


def affordances(category: str) -> frozenset[str]:
    """The affordances (static facts) of a category; parts are never movable."""
    return get_category(category).affordances


def is_part_category(category: str) -> bool:
    """True for part categories (drawer, compartment, region ...)."""
    return get_category(category).part


def normalize_color(word: str) -> str | None:
    """The palette colour a word denotes, or None."""
    w = word.lower()
    w = COLOR_SYNONYMS.get(w, w)
    return w if w in COLORS else None


def strip_instance(name: str) -> str:
    """``red_cube1`` -> ``red_cube``, ``alphabet_soup_1`` -> ``alphabet_soup``, ``teapot.n.01_1`` -> ``teapot``."""
    base = name.lower().rsplit("/", 1)[-1]
    base = base.split(".", 1)[0] if ".n." in base or ".v." in base else base
    stripped = _NUMERIC_SUFFIX.sub("", base)
    return stripped or base


def category_of(name_or_asset: str) -> tuple[str, dict[str, str | int]]:
    """Parse a node name or asset name into ``(category, attributes)``; never raises."""
    parsed = _parse(str(name_or_asset))
    return parsed.category, dict(parsed.attributes)


@lru_cache(maxsize=4096)
def _parse(raw: str) -> ParsedName:
    base = strip_instance(raw)
    if base in ASSETS:
        cat, attrs = ASSETS[base]
        return ParsedName(cat, dict(attrs))
    tokens = [t for t in re.split(r"[_\-\s]+", base) if t]
    if not tokens:
        return ParsedName("thing")
    span = _match_category(tokens)
    if span is None:
        return ParsedName("thing", _describe(tokens, "thing"))
    cat, (i, j) = span
    rest = tokens[:i] + tokens[j:]
    return ParsedName(cat, _describe(rest, cat))


def _match_category(tokens: list[str]) -> tuple[str, tuple[int, int]] | None:
    """The longest token span naming a category: suffixes first (head nouns), then prefixes, then any."""
    n = len(tokens)
    for i in range(n):  # longest suffix first: akita_black_bowl -> bowl, orange_juice -> orange_juice
        cat = canonical("_".join(tokens[i:]))
        if cat is not None:
            return cat, (i, n)
    for j in range(n - 1, 0, -1):  # then prefixes: drawer_low -> drawer
        cat = canonical("_".join(tokens[:j]))
        if cat is not None:
            return cat, (0, j)
    for length in range(n - 1, 0, -1):  # then any inner span
        for i in range(1, n - length):
            cat = canonical("_".join(tokens[i : i + length]))
            if cat is not None:
                return cat, (i, i + length)
    return None


def _describe(tokens: list[str], category: str) -> dict[str, str | int]:
    """Colour, material, size and (for drawers) level attributes from leftover name tokens."""
    attrs: dict[str, str | int] = {}
    colors = [c for c in (normalize_color(t) for t in tokens) if c]
    if colors:
        attrs["color"] = colors[0]
        if len(colors) > 1:
            attrs["secondary_color"] = colors[1]
    for t in tokens:
        if t in MATERIALS and "material" not in attrs:
            attrs["material"] = "wooden" if t == "wood" else t
        elif t in SIZES and "size" not in attrs:
            attrs["size"] = t
        elif category == "drawer" and t in LEVEL_WORDS and "level" not in attrs:
            attrs["level"] = LEVEL_WORDS[t]
    return attrs
