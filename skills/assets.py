"""Procedural assets: URDF models (primitives only) for every object the suites name.

:func:`make_asset` builds an :class:`AssetModel` from a category or asset name, an optional size
(extent x, y, z in metres) and a colour; :func:`asset_urdf_path` writes its URDF to a content-addressed
cache file (same inputs, same file), so worlds are deterministic and loading is cheap. Grasp sites are
laid out so the Panda's 8 cm gripper can hold each object: small objects across their narrow side,
hollow ones (bowls, plates, boxes, baskets, mugs) by a wall rim.
"""

from __future__ import annotations

import hashlib
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from gsr.skills.asset_model import Articulation, AssetModel, GraspSite, Interior
from gsr.skills.fixtures import (
    make_button,
    make_cabinet,
    make_lamp,
    make_microwave,
    make_rack,
    make_shelf,
    make_stove,
    make_table,
)
from gsr.skills.shapes import T, color_rgba, open_box, ring, scale
from gsr.skills.urdf import RGBA, Joint, Link, Vec, box, cylinder, urdf_text

from gsr.categories import category_of, get_category


def _solid(name: str, size: Vec, rgba: RGBA, mass: float, round_: bool = False) -> AssetModel:
    sx, sy, sz = size
    shape = cylinder((0, 0, sz / 2), sx / 2, sz, rgba) if round_ else box((0, 0, sz / 2), size, rgba)
    # grasp across the narrow horizontal side, a little below the top so the fingers hold firmly
    yaw = 0.0 if sx <= sy else math.pi / 2
    grip_z = max(sz - 0.025, sz * 0.5)
    return AssetModel(
        name,
        [Link("base", (shape,), mass)],
        grasps=[GraspSite("base", (0, 0, grip_z), yaw, width=min(sx, sy))],
        extent=size,
    )


def _round_open(name: str, size: Vec, rgba: RGBA, mass: float, floor: float = T) -> AssetModel:
    """A bowl, plate, mug or cup: a floor disc and a rim wall; grasped by the rim nearest the robot."""
    sx, _, sz = size
    r = sx / 2 - T / 2
    shapes = [cylinder((0, 0, floor / 2), sx / 2, floor, rgba), *ring(r, sz, rgba)]
    return AssetModel(
        name,
        [Link("base", tuple(shapes), mass)],
        grasps=[GraspSite("base", (-r, 0, sz - 0.012), 0.0, width=T)],
        interiors={"": Interior("base", (0, 0, sz * 0.75), (sx - 2 * T, sx - 2 * T, sz * 1.5))},
        extent=size,
    )


def _boxlike(name: str, size: Vec, rgba: RGBA, mass: float) -> AssetModel:
    sx, sy, sz = size
    return AssetModel(
        name,
        [Link("base", tuple(open_box(sx, sy, sz, rgba)), mass)],
        grasps=[GraspSite("base", (-sx / 2 + T / 2, 0, sz - 0.012), 0.0, width=T)],
        interiors={"": Interior("base", (0, 0, sz * 0.75), (sx - 2 * T, sy - 2 * T, sz * 1.5))},
        extent=size,
    )


def make_cube(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A cube (GSR-Bench) or block (RLBench stacking)."""
    return _solid("cube", scale(size, (0.045, 0.045, 0.045)), rgba, 0.06)


def make_box(size: Vec | None, rgba: RGBA) -> AssetModel:
    """An open box; grasped by its front wall."""
    return _boxlike("box", scale(size, (0.16, 0.16, 0.08)), rgba, 0.25)


def make_lidded_box(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A box with a sliding lid (prismatic along local +y) and a grip fin on its -y side."""
    sx, sy, sz = scale(size, (0.16, 0.16, 0.08))
    shapes = [
        *open_box(sx, sy, sz, rgba),
        box((0, -sy / 2 - 0.02, sz * 0.55), (0.012, 0.04, sz * 0.9), rgba),
    ]
    lid_rgba = (*tuple(min(1.0, c * 0.8 + 0.15) for c in rgba[:3]), 1.0)
    lid = Link(
        "lid",
        (
            box((0, 0, 0.005), (sx, sy, 0.01), lid_rgba),
            box((0, -sy / 2 + 0.03, 0.025), (0.02, 0.02, 0.03), lid_rgba),
        ),
        0.05,
        parent="base",
        joint=Joint("prismatic", (0, 0, sz), (0, 1, 0), 0.0, sy + 0.01, damping=2.0, friction=0.2),
    )
    tab = GraspSite("lid", (0, -sy / 2 + 0.03, 0.03), 0.0, width=0.02)
    return AssetModel(
        "lidded_box",
        [Link("base", tuple(shapes), 0.3), lid],
        grasps=[GraspSite("base", (0, -sy / 2 - 0.03, sz - 0.015), 0.0, width=0.012)],
        articulations={"lid": Articulation("lid", "lid", 0.0, sy + 0.005, handle=tab)},
        interiors={"": Interior("base", (0, 0, sz * 0.5), (sx - 2 * T, sy - 2 * T, sz))},
        open_part="lid",
        extent=(sx, sy + 0.04, sz),
    )


def make_basket(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A basket: a deep open box."""
    return _boxlike("basket", scale(size, (0.2, 0.16, 0.1)), rgba, 0.3)


def make_tray(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A shallow open tray."""
    return _boxlike("tray", scale(size, (0.22, 0.16, 0.04)), rgba, 0.25)


def make_caddy(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A desk caddy with four compartments: ``left`` (+y) and ``right`` (-y) bins along the whole depth,
    the middle split into ``front`` (-x, towards the robot) and ``back``.

    Every compartment holds a standing book (3 x 13 x 10 cm) with its long side along the compartment's
    long side: the side bins are 16.8 cm deep, the middle cells 15 cm wide (LIBERO's study scenes put
    a book into each of the four).
    """
    sx, sy, sz = scale(size, (0.184, 0.332, 0.08))
    side = (sy - 4 * T) * 0.25  # width of a side bin; the middle column gets the rest
    mid = sy - 4 * T - 2 * side
    y_div = mid / 2 + T / 2  # the two long dividers, at +-y_div
    shapes = [
        *open_box(sx, sy, sz, rgba),
        box((0, y_div, sz * 0.45), (sx - 2 * T, T, sz * 0.9), rgba),
        box((0, -y_div, sz * 0.45), (sx - 2 * T, T, sz * 0.9), rgba),
        box((0, 0, sz * 0.45), (T, mid, sz * 0.9), rgba),
    ]
    depth, cell = sx - 2 * T, (sx - 3 * T) / 2
    y_side = y_div + T / 2 + side / 2
    return AssetModel(
        "caddy",
        [Link("base", tuple(shapes), 0.3)],
        grasps=[GraspSite("base", (-sx / 2 + T / 2, 0, sz - 0.012), 0.0, width=T)],
        interiors={
            "": Interior("base", (0, 0, sz * 0.75), (sx - 2 * T, sy - 2 * T, sz * 1.5)),
            "compartment_front": Interior("base", (-(cell + T) / 2, 0, sz * 0.75), (cell, mid, sz * 1.5)),
            "compartment_back": Interior("base", ((cell + T) / 2, 0, sz * 0.75), (cell, mid, sz * 1.5)),
            "compartment_left": Interior("base", (0, y_side, sz * 0.75), (depth, side, sz * 1.5)),
            "compartment_right": Interior("base", (0, -y_side, sz * 0.75), (depth, side, sz * 1.5)),
        },
        extent=(sx, sy, sz),
    )


def make_bowl(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A bowl (a supporter: things go on it)."""
    return _round_open("bowl", scale(size, (0.13, 0.13, 0.055)), rgba, 0.15)


def make_plate(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A deep plate: a disc with a 2.5 cm rim so the gripper can take the rim."""
    return _round_open("plate", scale(size, (0.18, 0.18, 0.03)), rgba, 0.15)


def make_mug(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A mug with a handle keypoint on +y; grasped by its rim."""
    sx, _sy, sz = scale(size, (0.08, 0.08, 0.09))
    m = _round_open("mug", (sx, sx, sz), rgba, 0.12)
    handle = [box((0, sx / 2 + 0.015, sz * 0.5), (0.012, 0.03, sz * 0.6), rgba)]
    m.links = [Link("base", (*m.links[0].shapes, *handle), 0.12)]
    m.keypoints = {"handle": ("base", (0, sx / 2 + 0.025, sz * 0.5))}
    m.extent = (sx, sx + 0.06, sz)
    if sx <= 0.06:
        # a small mug (GSR-Bench's is 4.4 cm): a finger inside would touch the far wall, so the whole
        # body is held, closing along x (the handle sticks out along +y, clear of the fingers)
        m.grasps = [GraspSite("base", (0, 0, max(sz - 0.02, sz * 0.5)), 0.0, width=sx)]
    return m


def make_book(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A book standing on its edge (3 cm thick), grasped across its thickness."""
    return _solid("book", scale(size, (0.03, 0.13, 0.1)), rgba, 0.1)


def make_bottle(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A bottle: a cylinder with a shoulder, grasped just below its top (the palm must clear the top)."""
    sx, _, sz = scale(size, (0.06, 0.06, 0.2))
    shapes = (
        cylinder((0, 0, sz * 0.45), sx / 2, sz * 0.9, rgba),
        cylinder((0, 0, sz * 0.95), sx / 2 - 0.008, sz * 0.1, rgba),
    )
    return AssetModel(
        "bottle",
        [Link("base", shapes, 0.3)],
        grasps=[GraspSite("base", (0, 0, sz * 0.9 - 0.02), 0.0, width=sx)],
        extent=(sx, sx, sz),
    )


#: Food package shapes: (extent x, y, z, round?) — small enough for the 8 cm gripper.
FOOD: dict[str, tuple[float, float, float, bool]] = {
    "milk": (0.06, 0.06, 0.12, False),
    "orange_juice": (0.06, 0.06, 0.12, False),
    "popcorn": (0.05, 0.09, 0.1, False),
    "macaroni_and_cheese": (0.05, 0.09, 0.1, False),
    "cookie_box": (0.05, 0.12, 0.09, False),
    "cream_cheese": (0.05, 0.07, 0.035, False),
    "butter": (0.045, 0.08, 0.035, False),
    "chocolate_pudding": (0.05, 0.06, 0.04, False),
    "alphabet_soup": (0.065, 0.065, 0.08, True),
    "tomato_sauce": (0.06, 0.06, 0.09, True),
    "ketchup": (0.05, 0.05, 0.12, True),
    "bbq_sauce": (0.05, 0.05, 0.12, True),
    "salad_dressing": (0.05, 0.05, 0.13, True),
}
FOOD_COLORS: dict[str, str] = {
    "milk": "white",
    "orange_juice": "orange",
    "popcorn": "red",
    "ketchup": "red",
    "bbq_sauce": "brown",
    "alphabet_soup": "red",
    "tomato_sauce": "red",
    "cream_cheese": "silver",
    "butter": "yellow",
    "chocolate_pudding": "brown",
    "salad_dressing": "green",
    "macaroni_and_cheese": "orange",
    "cookie_box": "blue",
}


def _food(category: str) -> Callable[[Vec | None, RGBA], AssetModel]:
    sx, sy, sz, rnd = FOOD[category]

    def build(size: Vec | None, rgba: RGBA) -> AssetModel:
        return _solid(category, scale(size, (sx, sy, sz)), rgba, 0.12, round_=rnd)

    build.__doc__ = f"A {category.replace('_', ' ')} package."
    return build


def _simple(name: str, default: Vec, round_: bool = False) -> Callable[[Vec | None, RGBA], AssetModel]:
    def build(size: Vec | None, rgba: RGBA) -> AssetModel:
        return _solid(name, scale(size, default), rgba, 0.15, round_=round_)

    return build


BUILDERS: dict[str, Callable[[Vec | None, RGBA], AssetModel]] = {
    "cube": make_cube,
    "block": make_cube,
    "box": make_box,
    "lidded_box": make_lidded_box,
    "basket": make_basket,
    "tray": make_tray,
    "caddy": make_caddy,
    "bowl": make_bowl,
    "ramekin": lambda s, c: _round_open("ramekin", scale(s, (0.09, 0.09, 0.04)), c, 0.1),
    "plate": make_plate,
    "mug": make_mug,
    "cup": lambda s, c: _round_open("cup", scale(s, (0.07, 0.07, 0.08)), c, 0.08),
    "cabinet": make_cabinet,
    "stove": make_stove,
    "microwave": make_microwave,
    "lamp": make_lamp,
    "button": make_button,
    "switch": make_button,
    "rack": make_rack,
    "shelf": make_shelf,
    "book": make_book,
    "bottle": make_bottle,
    "wine_bottle": make_bottle,
    "pot": _simple("pot", (0.07, 0.07, 0.1), round_=True),
    "moka_pot": _simple("moka_pot", (0.06, 0.06, 0.12), round_=True),
    "pan": lambda s, c: _round_open("pan", scale(s, (0.16, 0.16, 0.035)), c, 0.3),
    "table": make_table,
    "thing": _simple("thing", (0.05, 0.05, 0.05)),
    **{food: _food(food) for food in FOOD},
}


def asset_category(asset: str) -> str:
    """The builder name for an asset or category name (``akita_black_bowl`` -> ``bowl``)."""
    key = asset.lower()
    if key in BUILDERS:
        return key
    category = get_category(category_of(key)[0]).name
    return category if category in BUILDERS else "thing"


def default_color(asset: str) -> str | None:
    """The colour an asset name implies (``akita_black_bowl`` -> black; food packages have their own)."""
    attrs = category_of(asset.lower())[1]
    color = attrs.get("color")
    if isinstance(color, str):
        return color
    return FOOD_COLORS.get(asset_category(asset))


def make_asset(asset: str, size: Vec | None = None, color: str | None = None) -> AssetModel:
    """The procedural model for an asset or category name, optionally resized and coloured."""
    kind = asset_category(asset)
    return BUILDERS[kind](size, color_rgba(color or default_color(asset)))


def cache_dir() -> Path:
    """Where generated URDF files go (``$GSR_ASSET_CACHE`` or a per-user temp folder)."""
    root = os.environ.get("GSR_ASSET_CACHE") or os.path.join(
        tempfile.gettempdir(), f"gsr-assets-{os.getuid()}"
    )
    path = Path(root)
    path.mkdir(parents=True, exist_ok=True)
    return path


def asset_urdf_path(model: AssetModel) -> Path:
    """Write the model's URDF to a content-addressed cache file (atomically) and return its path."""
    text = urdf_text(model.name, model.links)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    path = cache_dir() / f"{model.name}-{digest}.urdf"
    if not path.exists():
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    return path
