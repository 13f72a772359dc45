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

from gsr.categories import category_of, get_category
from skills.asset_model import Articulation, AssetModel, GraspSite, Interior
from skills.urdf import RGBA, Joint, Link, Shape, Vec, box, cylinder, urdf_text

#: Palette colour -> RGBA (the gsr.categories colour words).
PALETTE: dict[str, RGBA] = {
    "red": (0.85, 0.1, 0.1, 1),
    "blue": (0.1, 0.25, 0.85, 1),
    "yellow": (0.95, 0.85, 0.1, 1),
    "green": (0.1, 0.7, 0.2, 1),
    "black": (0.08, 0.08, 0.08, 1),
    "white": (0.95, 0.95, 0.95, 1),
    "orange": (0.95, 0.5, 0.05, 1),
    "purple": (0.5, 0.15, 0.7, 1),
    "pink": (0.95, 0.5, 0.7, 1),
    "brown": (0.5, 0.3, 0.12, 1),
    "grey": (0.5, 0.5, 0.5, 1),
    "gold": (0.85, 0.7, 0.2, 1),
    "silver": (0.75, 0.75, 0.78, 1),
    "cyan": (0.1, 0.8, 0.85, 1),
}
WOOD: RGBA = (0.6, 0.42, 0.25, 1)
METAL: RGBA = (0.3, 0.3, 0.32, 1)
T = 0.008  # wall thickness


def color_rgba(color: str | None, default: RGBA = (0.7, 0.7, 0.7, 1)) -> RGBA:
    """RGBA for a palette colour name (``None`` or unknown -> ``default``)."""
    return PALETTE.get((color or "").lower(), default)


def _scale(size: Vec | None, default: Vec) -> Vec:
    return tuple(default) if size is None else tuple(float(v) for v in size)  # type: ignore[return-value]


def _ring(radius: float, height: float, rgba: RGBA, z0: float = 0.0, n: int = 14) -> list[Shape]:
    """Wall segments of a round cup/bowl/plate rim (radius to the wall's centre line)."""
    seg = 2 * radius * math.sin(math.pi / n) * 1.08
    return [
        Shape(
            "box",
            (radius * math.cos(2 * math.pi * i / n), radius * math.sin(2 * math.pi * i / n), z0 + height / 2),
            (T, seg, height),
            rgba,
            rpy=(0.0, 0.0, 2 * math.pi * i / n),
        )
        for i in range(n)
    ]


def _open_box(sx: float, sy: float, sz: float, rgba: RGBA, z0: float = 0.0) -> list[Shape]:
    """Floor and four walls of an open box of outer extents (sx, sy, sz) standing at z0."""
    return [
        box((0, 0, z0 + T / 2), (sx, sy, T), rgba),
        box((-sx / 2 + T / 2, 0, z0 + sz / 2), (T, sy, sz), rgba),
        box((sx / 2 - T / 2, 0, z0 + sz / 2), (T, sy, sz), rgba),
        box((0, -sy / 2 + T / 2, z0 + sz / 2), (sx - 2 * T, T, sz), rgba),
        box((0, sy / 2 - T / 2, z0 + sz / 2), (sx - 2 * T, T, sz), rgba),
    ]


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
    shapes = [cylinder((0, 0, floor / 2), sx / 2, floor, rgba), *_ring(r, sz, rgba)]
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
        [Link("base", tuple(_open_box(sx, sy, sz, rgba)), mass)],
        grasps=[GraspSite("base", (-sx / 2 + T / 2, 0, sz - 0.012), 0.0, width=T)],
        interiors={"": Interior("base", (0, 0, sz * 0.75), (sx - 2 * T, sy - 2 * T, sz * 1.5))},
        extent=size,
    )


def make_cube(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A cube (GSR-Bench) or block (RLBench stacking)."""
    return _solid("cube", _scale(size, (0.045, 0.045, 0.045)), rgba, 0.06)


def make_box(size: Vec | None, rgba: RGBA) -> AssetModel:
    """An open box; grasped by its front wall."""
    return _boxlike("box", _scale(size, (0.16, 0.16, 0.08)), rgba, 0.25)


def make_lidded_box(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A box with a sliding lid (prismatic along local +y) and a grip fin on its -y side."""
    sx, sy, sz = _scale(size, (0.16, 0.16, 0.08))
    shapes = [
        *_open_box(sx, sy, sz, rgba),
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
    return _boxlike("basket", _scale(size, (0.2, 0.16, 0.1)), rgba, 0.3)


def make_tray(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A shallow open tray."""
    return _boxlike("tray", _scale(size, (0.22, 0.16, 0.04)), rgba, 0.25)


def make_caddy(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A desk caddy with a divider: compartment_0 (front, -x) and compartment_1 (back)."""
    sx, sy, sz = _scale(size, (0.2, 0.14, 0.08))
    shapes = [*_open_box(sx, sy, sz, rgba), box((0, 0, sz * 0.4), (T, sy - 2 * T, sz * 0.8), rgba)]
    half = (sx - 3 * T) / 2
    return AssetModel(
        "caddy",
        [Link("base", tuple(shapes), 0.3)],
        grasps=[GraspSite("base", (-sx / 2 + T / 2, 0, sz - 0.012), 0.0, width=T)],
        interiors={
            "": Interior("base", (0, 0, sz * 0.75), (sx - 2 * T, sy - 2 * T, sz * 1.5)),
            "compartment_0": Interior("base", (-sx / 4, 0, sz * 0.75), (half, sy - 2 * T, sz * 1.5)),
            "compartment_1": Interior("base", (sx / 4, 0, sz * 0.75), (half, sy - 2 * T, sz * 1.5)),
        },
        extent=(sx, sy, sz),
    )


def make_bowl(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A bowl (a supporter: things go on it)."""
    return _round_open("bowl", _scale(size, (0.13, 0.13, 0.055)), rgba, 0.15)


def make_plate(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A deep plate: a disc with a 2.5 cm rim so the gripper can take the rim."""
    return _round_open("plate", _scale(size, (0.18, 0.18, 0.03)), rgba, 0.15)


def make_mug(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A mug with a handle keypoint on +y; grasped by its rim."""
    sx, _sy, sz = _scale(size, (0.08, 0.08, 0.09))
    m = _round_open("mug", (sx, sx, sz), rgba, 0.12)
    handle = [box((0, sx / 2 + 0.015, sz * 0.5), (0.012, 0.03, sz * 0.6), rgba)]
    m.links = [Link("base", (*m.links[0].shapes, *handle), 0.12)]
    m.keypoints = {"handle": ("base", (0, sx / 2 + 0.025, sz * 0.5))}
    m.extent = (sx, sx + 0.06, sz)
    return m


def make_cabinet(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A cabinet with three drawers (prismatic, opening towards local -x) and a top surface."""
    sx, sy, sz = _scale(size, (0.28, 0.36, 0.32))
    plinth, h = 0.04, (sz - 0.04 - T) / 3
    shapes = [
        box((0, 0, plinth / 2), (sx, sy, plinth), rgba),
        box((sx / 2 - T / 2, 0, sz / 2), (T, sy, sz), rgba),
        box((0, -sy / 2 + T / 2, sz / 2), (sx, T, sz), rgba),
        box((0, sy / 2 - T / 2, sz / 2), (sx, T, sz), rgba),
    ] + [box((0, 0, plinth + k * h), (sx, sy, 0.006), rgba) for k in (1, 2)]
    links = [Link("base", tuple(shapes), 20.0)]
    links.append(
        Link(
            "top_side", (box((0, 0, T / 2), (sx, sy, T), rgba),), 0.5, "base", Joint("fixed", (0, 0, sz - T))
        )
    )
    model = AssetModel("cabinet", links, fixed=True, extent=(sx, sy, sz), part_links={"top_side": "top_side"})
    dx, dy, dz = sx - 2 * T, sy - 2 * T - 0.004, h - 0.012
    front = (*tuple(min(1.0, c * 0.85 + 0.1) for c in rgba[:3]), 1.0)
    for k in range(3):
        name = f"drawer_{k}"
        shapes = [*_open_box(dx - T, dy, dz * 0.8, rgba)]
        # the front panel and a pull bar standing 2.5 cm off it
        shapes.append(box((-dx / 2, 0, dz / 2), (T, sy - 0.006, dz), front))
        # a vertical bar 4.5 cm off the front: a tilted hand closing sideways round it stays clear of the
        # panel and of the drawers above (its long axis runs along y, not up the cabinet)
        hy, bar = 0.0, dz * 0.6
        shapes.append(box((-dx / 2 - 0.045, hy, dz / 2), (0.012, 0.012, bar), METAL))
        shapes += [
            box((-dx / 2 - 0.024, hy, dz / 2 + s * (bar / 2 - 0.005)), (0.04, 0.01, 0.01), METAL)
            for s in (-1, 1)
        ]
        z = plinth + k * h + 0.006
        links.append(
            Link(
                name,
                tuple(shapes),
                0.8,
                "base",
                Joint("prismatic", (T / 2, 0, z), (-1, 0, 0), 0.0, dx * 0.9),
                friction=0.8,
            )
        )
        pull = GraspSite(name, (-dx / 2 - 0.045, hy, dz / 2), 0.0, approach="front", width=0.012)
        model.articulations[name] = Articulation(name, "drawer", 0.0, dx * 0.85, handle=pull)
        model.interiors[name] = Interior(name, (0, 0, dz * 0.5), (dx - 2 * T, dy - 2 * T, dz))
        model.keypoints[f"{name}/handle"] = (name, pull.xyz)
    return model


def make_stove(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A flat stove: a base, a burner surface and a knob (revolute about z; on when turned past 45 deg)."""
    sx, sy, sz = _scale(size, (0.26, 0.34, 0.05))
    base = Link(
        "base", (box((0, 0, sz / 2), (sx, sy, sz), rgba if rgba != (0.7, 0.7, 0.7, 1) else METAL),), 10.0
    )
    burner = Link(
        "burner",
        (cylinder((0, 0, 0.003), 0.08, 0.006, (0.15, 0.15, 0.15, 1)),),
        0.2,
        "base",
        Joint("fixed", (0.02, 0.05, sz)),
    )
    kx, ky = -sx / 2 + 0.05, -sy / 2 + 0.06
    knob = Link(
        "knob",
        (
            cylinder((0, 0, 0.006), 0.022, 0.012, (0.9, 0.9, 0.9, 1)),
            box((0, 0, 0.025), (0.05, 0.012, 0.026), (0.9, 0.2, 0.1, 1)),
        ),
        0.05,
        "base",
        Joint("revolute", (kx, ky, sz), (0, 0, 1), 0.0, math.pi / 2, damping=0.5, friction=0.05),
    )
    grip = GraspSite("knob", (0, 0, 0.03), math.pi / 2, width=0.012)
    return AssetModel(
        "stove",
        [base, burner, knob],
        articulations={"knob": Articulation("knob", "knob", 0.0, math.pi / 2, handle=grip)},
        part_links={"burner": "burner"},
        switch_part="knob",
        fixed=True,
        extent=(sx, sy, sz),
    )


def _button_link(name: str, xyz: Vec, rgba: RGBA) -> Link:
    return Link(
        name,
        (box((0, 0, 0.01), (0.03, 0.03, 0.02), rgba),),
        0.02,
        "base",
        Joint("prismatic", xyz, (0, 0, -1), 0.0, 0.012, damping=0.5, friction=0.0),
    )


def _button_art(name: str) -> Articulation:
    return Articulation(name, "button", 0.0, 0.012, handle=GraspSite(name, (0, 0, 0.02), 0.0, width=0.03))


def make_microwave(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A microwave: a cavity, a door hinged on its -y edge (revolute about z) and a power button on top."""
    sx, sy, sz = _scale(size, (0.26, 0.36, 0.22))
    shapes = [
        box((0, 0, T / 2), (sx, sy, T), rgba),
        box((0, 0, sz - T / 2), (sx, sy, T), rgba),
        box((sx / 2 - T / 2, 0, sz / 2), (T, sy, sz), rgba),
        box((0, -sy / 2 + T / 2, sz / 2), (sx, T, sz), rgba),
        box((0, sy / 2 - T / 2, sz / 2), (sx, T, sz), rgba),
    ]
    door_w = sy
    door = Link(
        "door",
        (
            box((-T / 2, door_w / 2, sz / 2), (T, door_w, sz - 0.01), (0.2, 0.2, 0.25, 1)),
            box((-0.03, door_w - 0.03, sz / 2), (0.012, 0.012, 0.1), METAL),
            box((-0.017, door_w - 0.03, sz / 2 - 0.045), (0.026, 0.01, 0.01), METAL),
            box((-0.017, door_w - 0.03, sz / 2 + 0.045), (0.026, 0.01, 0.01), METAL),
        ),
        0.3,
        "base",
        Joint("revolute", (-sx / 2, -sy / 2, 0.0), (0, 0, -1), 0.0, 1.9, damping=0.5, friction=0.05),
    )
    handle = GraspSite("door", (-0.03, door_w - 0.03, sz / 2), 0.0, approach="front", width=0.012)
    return AssetModel(
        "microwave",
        [
            Link("base", tuple(shapes), 8.0),
            door,
            _button_link("button", (-sx / 2 + 0.04, sy / 2 - 0.05, sz), (0.1, 0.7, 0.2, 1)),
        ],
        articulations={
            "door": Articulation("door", "door", 0.0, 1.6, handle=handle),
            "button": _button_art("button"),
        },
        interiors={"": Interior("base", (0, 0, sz / 2), (sx - 2 * T, sy - 2 * T, sz - 2 * T))},
        open_part="door",
        switch_part="button",
        fixed=True,
        extent=(sx, sy, sz),
    )


def make_lamp(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A desk lamp: a long base with a push switch at the front, the pole and a small shade at the back."""
    sx, sy, sz = _scale(size, (0.18, 0.12, 0.3))
    shapes = (
        box((0, 0, 0.015), (sx, sy, 0.03), rgba),
        cylinder((sx / 2 - 0.025, 0, sz / 2), 0.01, sz, METAL),
        cylinder((sx / 2 - 0.025, 0, sz - 0.03), 0.04, 0.06, (0.95, 0.9, 0.6, 1)),
    )
    return AssetModel(
        "lamp",
        [Link("base", shapes, 3.0), _button_link("switch", (-sx / 2 + 0.03, 0, 0.03), (0.9, 0.9, 0.9, 1))],
        articulations={"switch": _button_art("switch")},
        switch_part="switch",
        fixed=True,
        extent=(sx, sy, sz),
    )


def make_button(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A push button on a base plate."""
    sx, sy, _ = _scale(size, (0.08, 0.08, 0.03))
    return AssetModel(
        "button",
        [
            Link("base", (box((0, 0, 0.01), (sx, sy, 0.02), METAL),), 2.0),
            _button_link("button", (0, 0, 0.02), rgba),
        ],
        articulations={"button": _button_art("button")},
        switch_part="button",
        fixed=True,
        extent=(sx, sy, 0.04),
    )


def make_rack(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A wine/dish rack: a platform with side rails (a supporter fixture)."""
    sx, sy, sz = _scale(size, (0.16, 0.26, 0.06))
    c = rgba if rgba != (0.7, 0.7, 0.7, 1) else WOOD
    shapes = (
        box((0, 0, sz / 2), (sx, sy, sz), c),
        box((-sx / 2 + 0.005, 0, sz + 0.01), (0.01, sy, 0.02), c),
        box((sx / 2 - 0.005, 0, sz + 0.01), (0.01, sy, 0.02), c),
    )
    return AssetModel("rack", [Link("base", shapes, 5.0)], fixed=True, extent=(sx, sy, sz))


def make_shelf(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A low two-level shelf (a supporter fixture)."""
    sx, sy, sz = _scale(size, (0.2, 0.4, 0.12))
    c = rgba if rgba != (0.7, 0.7, 0.7, 1) else WOOD
    return AssetModel(
        "shelf", [Link("base", (box((0, 0, sz / 2), (sx, sy, sz), c),), 5.0)], fixed=True, extent=(sx, sy, sz)
    )


def make_book(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A book standing on its edge (3 cm thick), grasped across its thickness."""
    return _solid("book", _scale(size, (0.03, 0.13, 0.1)), rgba, 0.1)


def make_bottle(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A bottle: a cylinder with a shoulder, grasped just below its top (the palm must clear the top)."""
    sx, _, sz = _scale(size, (0.06, 0.06, 0.2))
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
        return _solid(category, _scale(size, (sx, sy, sz)), rgba, 0.12, round_=rnd)

    build.__doc__ = f"A {category.replace('_', ' ')} package."
    return build


def _simple(name: str, default: Vec, round_: bool = False) -> Callable[[Vec | None, RGBA], AssetModel]:
    def build(size: Vec | None, rgba: RGBA) -> AssetModel:
        return _solid(name, _scale(size, default), rgba, 0.15, round_=round_)

    return build


def make_table(size: Vec | None, rgba: RGBA) -> AssetModel:
    """The table: a slab whose top face is the asset's z = 0 plane (the base frame sits on the top)."""
    sx, sy, _ = _scale(size, (1.2, 1.6, 0.05))
    return AssetModel(
        "table",
        [Link("base", (box((0, 0, -0.025), (sx, sy, 0.05), WOOD),), 0.0)],
        fixed=True,
        extent=(sx, sy, 0.05),
    )


BUILDERS: dict[str, Callable[[Vec | None, RGBA], AssetModel]] = {
    "cube": make_cube,
    "block": make_cube,
    "box": make_box,
    "lidded_box": make_lidded_box,
    "basket": make_basket,
    "tray": make_tray,
    "caddy": make_caddy,
    "bowl": make_bowl,
    "ramekin": lambda s, c: _round_open("ramekin", _scale(s, (0.09, 0.09, 0.04)), c, 0.1),
    "plate": make_plate,
    "mug": make_mug,
    "cup": lambda s, c: _round_open("cup", _scale(s, (0.07, 0.07, 0.08)), c, 0.08),
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
    "pan": lambda s, c: _round_open("pan", _scale(s, (0.16, 0.16, 0.035)), c, 0.3),
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
