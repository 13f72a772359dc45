"""Scene sampling for the dataset generator: objects from the catalog and a consistent initial state.

A :class:`Scene` is the static part (which objects, their categories, colours, parts, home positions
on the table); a state is a set of ground atoms of the tabletop domain. The initial state respects the
domain's validity rules (no container inside a container, nothing on a non-supporter, a drawer holds
things whether open or closed), so every state the generator plans from is one the checker accepts.
Node ids follow a per-scene naming style (the Manip-Cognition "name swap" augmentation): the same
content appears as ``red_cube_3``, ``cube_3`` or ``block_of_red_3`` style names across scenes.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

from gsr.categories import affordances, synonyms
from gsr.datagen.catalog import Catalog, CatalogEntry
from gsr.pddl.model import Atom

#: Colours that never appear in train/val scenes (the unseen-colour test split).
HELDOUT_COLORS: frozenset[str] = frozenset({"cyan", "gold"})
#: Id naming styles (name-swap augmentation).
NAME_STYLES: tuple[str, ...] = ("descriptive", "plain", "synonym")
TABLE_X = (-0.45, 0.35)  # free area of the table for movable objects (x is away from the robot)
TABLE_Y = (-0.7, 0.7)


@dataclass(frozen=True, slots=True)
class SceneObject:
    """One node of a generated scene: a catalog instance or one of its parts."""

    id: str
    category: str
    kind: str  # catalog entry name (or part name)
    role: str  # table, fixture, part, container, supporter, item
    affordances: frozenset[str]
    color: str | None = None
    material: str | None = None
    parent: str | None = None
    level: int | None = None
    size: tuple[float, float, float] = (0.1, 0.1, 0.1)
    keypoints: tuple[str, ...] = ()
    home: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def movable(self) -> bool:
        """True when the object can be picked."""
        return "movable" in self.affordances


@dataclass(slots=True)
class Scene:
    """A sampled scene: objects (nodes in canonical order) and its held-out tag."""

    objects: list[SceneObject]
    heldout: str | None = None  # None (train/val), "pair", "color" or "horizon"
    name_style: str = "descriptive"
    by_id: dict[str, SceneObject] = field(default_factory=dict)
    node_bases: list[dict] = field(default_factory=list)  # static JSON node dicts (filled by serialize)

    def __post_init__(self) -> None:
        self.by_id = {o.id: o for o in self.objects}

    def with_role(self, *roles: str) -> list[SceneObject]:
        """Objects with one of these roles, in canonical order."""
        return [o for o in self.objects if o.role in roles]


def _pick_color(rng: random.Random, entry: CatalogEntry, heldout_color: bool) -> str:
    allowed = [c for c in entry.colors if c not in HELDOUT_COLORS]
    if heldout_color:
        special = [c for c in entry.colors if c in HELDOUT_COLORS]
        if special:
            return rng.choice(special)
    return rng.choice(allowed or list(entry.colors))


def _make_id(style: str, entry: CatalogEntry, color: str, number: int, rng: random.Random) -> str:
    noun = entry.name
    if style == "synonym":
        words = [s for s in synonyms(entry.category) if "_" not in s or len(s) < 14]
        noun = rng.choice(words) if words and entry.category != "thing" else noun
    if style == "plain":
        return f"{noun}_{number}"
    if noun.startswith(f"{color}_") or f"_{color}_" in noun:
        return f"{noun}_{number}"
    return f"{color}_{noun}_{number}"


def _grid_slots(rng: random.Random, n: int) -> list[tuple[float, float]]:
    """``n`` distinct table positions on a jittered 0.15 m grid (no two objects overlap)."""
    xs = [TABLE_X[0] + 0.15 * i for i in range(int((TABLE_X[1] - TABLE_X[0]) / 0.15) + 1)]
    ys = [TABLE_Y[0] + 0.15 * j for j in range(int((TABLE_Y[1] - TABLE_Y[0]) / 0.15) + 1)]
    cells = [(x, y) for x in xs for y in ys]
    chosen = rng.sample(cells, n)
    return [
        (round(x + rng.uniform(-0.02, 0.02), 3), round(y + rng.uniform(-0.02, 0.02), 3)) for x, y in chosen
    ]


def sample_scene(
    rng: random.Random, catalog: Catalog, heldout: str | None = None, size: tuple[int, int] = (4, 8)
) -> Scene:
    """A random scene: a table, 0-2 fixtures, 1-2 containers, 1-2 supporters and ``size`` items."""
    style = rng.choice(NAME_STYLES)
    heldout_color = heldout == "color"
    objects: list[SceneObject] = [
        SceneObject("table", "table", "table", "table", frozenset({"supporter"}), size=(1.2, 1.6, 0.02))
    ]
    used: set[str] = {"table"}
    numbers = list(range(1, 10))
    rng.shuffle(numbers)  # instance numbers carry no order information

    def new_id(entry: CatalogEntry, color: str) -> str:
        for n in rng.sample(numbers, len(numbers)):
            oid = _make_id(style, entry, color, n, rng)
            if oid not in used:
                used.add(oid)
                return oid
        raise AssertionError("ran out of instance numbers")  # 9 per base name is more than any scene uses

    fixtures = [f for f in catalog.by_role("fixture") if f.category != "table"]  # the table is always there
    n_fixtures = rng.choice((0, 1, 1, 2, 2))
    chosen_fixtures: list[CatalogEntry] = []
    for entry in rng.sample(fixtures, len(fixtures)):
        if len(chosen_fixtures) == n_fixtures:
            break
        if entry.category == "cabinet" and any(f.category == "cabinet" for f in chosen_fixtures):
            continue
        chosen_fixtures.append(entry)
    movable_plan = (
        [rng.choice(catalog.by_role("container")) for _ in range(rng.randint(1, 2))]
        + [rng.choice(catalog.by_role("supporter")) for _ in range(rng.randint(1, 2))]
        + [rng.choice(catalog.by_role("item")) for _ in range(rng.randint(*size))]
    )
    # fixtures stand along the far edge of the table; movable objects get grid slots in front
    for k, entry in enumerate(chosen_fixtures):
        color = _pick_color(rng, entry, False)
        oid = f"{entry.name}_{rng.choice(numbers)}" if style != "synonym" else new_id(entry, color)
        if oid in used:
            oid = new_id(entry, color)
        used.add(oid)
        home = (0.5, -0.5 + 1.0 * k, 0.0)
        objects.append(
            SceneObject(
                oid,
                entry.node_category,
                entry.name,
                "fixture",
                frozenset(entry.affordances),
                color,
                entry.material,
                size=entry.size,
                keypoints=entry.keypoints,
                home=home,
            )
        )
        for part in entry.parts:
            level = part.level
            z = entry.size[2] if part.category == "cabinet_top" else 0.05 + 0.18 * (level or 0)
            objects.append(
                SceneObject(
                    f"{oid}/{part.name}",
                    part.category,
                    part.name,
                    "part",
                    frozenset(part.affordances),
                    parent=oid,
                    level=level,
                    size=(entry.size[0], entry.size[1], 0.15),
                    keypoints=part.keypoints,
                    home=(home[0], home[1], round(z, 3)),
                )
            )
    slots = _grid_slots(rng, len(movable_plan))
    for entry, (x, y) in zip(movable_plan, slots, strict=True):
        color = _pick_color(rng, entry, heldout_color)
        aff = frozenset(affordances(entry.category))
        objects.append(
            SceneObject(
                new_id(entry, color),
                entry.node_category,
                entry.name,
                entry.role,
                aff,
                color,
                entry.material,
                size=entry.size,
                keypoints=entry.keypoints,
                home=(x, y, 0.0),
            )
        )
    if heldout_color and not any(o.color in HELDOUT_COLORS for o in objects):
        # force one unseen colour: recolour the first item whose entry offers one
        for i, o in enumerate(objects):
            entry = catalog.entry(o.kind) if o.role in ("item", "container", "supporter") else None
            special = [c for c in entry.colors if c in HELDOUT_COLORS] if entry else []
            if special:
                objects[i] = _recolored(o, special[0], entry, style, used, numbers, rng)
                break
    return Scene(objects, heldout, style)


def _recolored(
    o: SceneObject, color: str, entry: CatalogEntry, style: str, used: set[str], numbers: list[int], rng
) -> SceneObject:
    used.discard(o.id)
    for n in numbers:
        oid = _make_id(style, entry, color, n, rng)
        if oid not in used:
            used.add(oid)
            break
    return SceneObject(
        oid,
        o.category,
        o.kind,
        o.role,
        o.affordances,
        color,
        o.material,
        size=o.size,
        keypoints=o.keypoints,
        home=o.home,
    )


def reskin(rng: random.Random, base: Scene, catalog: Catalog, heldout: str | None) -> Scene:
    """A new scene with the same structure as ``base`` (same roles, affordances, parts, drawer levels),
    but fresh object types, colours, names and table positions: it grounds to an isomorphic task."""
    style = rng.choice(NAME_STYLES)
    heldout_color = heldout == "color"
    used: set[str] = {"table"}
    numbers = list(range(1, 10))
    renamed: dict[str, str] = {"table": "table"}
    out: list[SceneObject] = []
    movable = [o for o in base.objects if o.movable]
    slots = iter(_grid_slots(rng, len(movable)))
    for o in base.objects:
        if o.role == "table":
            out.append(o)
            continue
        if o.role == "part":
            parent = renamed[o.parent] if o.parent else None
            new_id = f"{parent}/{o.kind}"
            renamed[o.id] = new_id
            out.append(_replace(o, id=new_id, parent=parent))
            continue
        if o.role == "fixture":
            entry = catalog.entry(o.kind)
        else:
            entry = rng.choice(_same_shape(catalog, o.role, o.affordances))
        color = _pick_color(rng, entry, heldout_color)
        for n in rng.sample(numbers, len(numbers)):
            oid = _make_id(style, entry, color, n, rng)
            if oid not in used:
                break
        used.add(oid)
        renamed[o.id] = oid
        home = o.home if o.role == "fixture" else (*next(slots), 0.0)
        out.append(
            SceneObject(
                oid,
                entry.node_category,
                entry.name,
                o.role,
                o.affordances,
                color,
                entry.material,
                size=entry.size,
                keypoints=entry.keypoints,
                home=home,
            )
        )
    scene = Scene(out, heldout, style)
    if heldout_color and not any(x.color in HELDOUT_COLORS for x in out):
        for i, x in enumerate(out):
            if x.role in ("item", "container", "supporter"):
                entry = catalog.entry(x.kind)
                special = [c for c in entry.colors if c in HELDOUT_COLORS]
                if special:
                    out[i] = _recolored(x, special[0], entry, style, used, numbers, rng)
                    return Scene(out, heldout, style)
    return scene


def _same_shape(catalog: Catalog, role: str, aff: frozenset[str]) -> list[CatalogEntry]:
    """Catalog entries of ``role`` whose category has exactly these affordances."""
    key = (id(catalog), role, aff)
    hit = _SHAPES.get(key)
    if hit is None:
        hit = _SHAPES[key] = [e for e in catalog.by_role(role) if frozenset(affordances(e.category)) == aff]
    return hit


_SHAPES: dict[tuple, list[CatalogEntry]] = {}


def _replace(o: SceneObject, **changes) -> SceneObject:
    from dataclasses import replace

    return replace(o, **changes)


def pair_key(obj: SceneObject, target: SceneObject) -> tuple[str, str]:
    """The (object type, target type) composition an ``on``/``in`` relation instantiates (parts by category)."""
    return (obj.kind, target.category if target.role == "part" else target.kind)


def fixed_surfaces(scene: Scene) -> list[SceneObject]:
    """Non-movable supporting surfaces (table, cabinet tops, shelves, racks)."""
    return [
        o
        for o in scene.objects
        if "supporter" in o.affordances and not o.movable and "switchable" not in o.affordances
    ]


def in_targets(scene: Scene) -> list[SceneObject]:
    """Everything something can be put IN (drawers, boxes, baskets, microwave, cabinet interior)."""
    return [o for o in scene.objects if "container" in o.affordances]


def on_targets(scene: Scene) -> list[SceneObject]:
    """Everything something can be put ON (table, plates, bowls, burners, cabinet tops, shelves)."""
    return [o for o in scene.objects if "supporter" in o.affordances]


def initial_atoms(
    rng: random.Random, scene: Scene, forbidden: frozenset[tuple[str, str]] = frozenset()
) -> frozenset[Atom]:
    """A random consistent initial support/door/power configuration (dynamic atoms only).

    ``forbidden`` holds (object kind, target kind) pairs that must not appear (held-out pairs).
    """
    atoms: set[Atom] = {Atom("hand_empty", ())}
    surfaces = fixed_surfaces(scene)
    containers = in_targets(scene)
    hosts = [o for o in on_targets(scene) if o.movable]  # plates, bowls, pans, boxes
    for o in scene.objects:
        if "openable" in o.affordances and rng.random() < 0.3:
            atoms.add(Atom("open", (o.id,)))
        if "switchable" in o.affordances and rng.random() < 0.25:
            atoms.add(Atom("turned_on", (o.id,)))
    # the table is weighted double: most things start on it, as in GSR-Bench and LIBERO scenes
    surface_choices = [("on", s) for s in surfaces for _ in range(2 if s.id == "table" else 1)]
    for o in scene.objects:
        if not o.movable:
            continue
        choices = list(surface_choices)
        if o.role == "item":  # only items go into containers or onto movable hosts: stacks stay one deep
            choices += [("in", c) for c in containers if c.id != o.id]
            choices += [("on", h) for h in hosts if h.id != o.id]
        choices = [(r, t) for r, t in choices if pair_key(o, t) not in forbidden]
        rel, target = rng.choice(choices)
        atoms.add(Atom(rel, (o.id, target.id)))
    return frozenset(atoms)
