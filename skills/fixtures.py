"""Procedural fixtures: cabinet with drawers, stove with knob, microwave, lamp, button, rack, shelf, table.

Articulated parts are real joints (prismatic drawers and buttons, revolute knob and door) with handles
the skills grasp; buttons are spring-loaded and the world latches their presses into on/off.
"""

from __future__ import annotations

import math

from gsr.skills.asset_model import Articulation, AssetModel, GraspSite, Interior
from gsr.skills.shapes import METAL, WOOD, T, open_box, scale
from gsr.skills.urdf import RGBA, Joint, Link, Shape, Vec, box, cylinder


def make_cabinet(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A cabinet with three drawers (prismatic, opening towards local -x) and a top surface."""
    sx, sy, sz = scale(size, (0.28, 0.36, 0.32))
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
        # side and back walls half the drawer's height: a hand closing on a 3 cm cube or a 5 cm mug in
        # the drawer keeps its underside (4 cm above the fingertips) clear of them anywhere inside
        shapes = [*open_box(dx - T, dy, dz * 0.5, rgba)]
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
    sx, sy, sz = scale(size, (0.26, 0.34, 0.05))
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
    sx, sy, sz = scale(size, (0.26, 0.36, 0.22))
    shapes = [
        # a 2 mm floor with a ramp before the opening: what is set down there slides in over it
        box((0, 0, 0.001), (sx, sy, 0.002), rgba),
        Shape("box", (-sx / 2 - 0.02, 0, -0.0032), (0.05, sy - 2 * T, 0.004), rgba, rpy=(0.0, -0.16, 0.0)),
        box((sx / 2 - T / 2, 0, sz / 2), (T, sy, sz), rgba),
        box((0, -sy / 2 + T / 2, sz / 2), (sx, T, sz), rgba),
        box((0, sy / 2 - T / 2, sz / 2), (sx, T, sz), rgba),
    ]
    door_w = sy
    door = Link(
        "door",
        (
            box((-T / 2, door_w / 2, sz / 2), (T, door_w, sz - 0.01), (0.2, 0.2, 0.25, 1)),
            # a vertical pull bar 4.5 cm off the door (as on the drawers: room for a tilted hand's fingers)
            box((-0.045, door_w - 0.04, sz / 2), (0.012, 0.012, 0.1), METAL),
            box((-0.024, door_w - 0.04, sz / 2 - 0.045), (0.04, 0.01, 0.01), METAL),
            box((-0.024, door_w - 0.04, sz / 2 + 0.045), (0.04, 0.01, 0.01), METAL),
        ),
        0.3,
        "base",
        # about +z: the free (+y) edge swings out towards the front (-x), away from the cavity
        Joint("revolute", (-sx / 2, -sy / 2, 0.0), (0, 0, 1), 0.0, 1.9, damping=0.5, friction=0.05),
    )
    handle = GraspSite("door", (-0.045, door_w - 0.04, sz / 2), 0.0, approach="front", width=0.012)
    return AssetModel(
        "microwave",
        [
            Link("base", tuple(shapes), 8.0),
            # the roof is a part of its own: things stand on the microwave's top side (LIBERO's bowl)
            Link(
                "top_side",
                (box((0, 0, T / 2), (sx, sy, T), rgba),),
                0.5,
                "base",
                Joint("fixed", (0, 0, sz - T)),
            ),
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
        part_links={"top_side": "top_side"},
        fixed=True,
        extent=(sx, sy, sz),
    )


def make_lamp(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A desk lamp: a long base with a push switch at the front, the pole and a small shade at the back."""
    sx, sy, sz = scale(size, (0.18, 0.12, 0.3))
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
    sx, sy, _ = scale(size, (0.08, 0.08, 0.03))
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
    sx, sy, sz = scale(size, (0.16, 0.26, 0.06))
    c = rgba if rgba != (0.7, 0.7, 0.7, 1) else WOOD
    shapes = (
        box((0, 0, sz / 2), (sx, sy, sz), c),
        box((-sx / 2 + 0.005, 0, sz + 0.01), (0.01, sy, 0.02), c),
        box((sx / 2 - 0.005, 0, sz + 0.01), (0.01, sy, 0.02), c),
    )
    return AssetModel("rack", [Link("base", shapes, 5.0)], fixed=True, extent=(sx, sy, sz))


def make_shelf(size: Vec | None, rgba: RGBA) -> AssetModel:
    """A two-layer shelf built as three steps, each open from above: the ``bottom_region`` board in
    front (-x), the ``top_region`` layer a third further back at half height, the ``top_side`` at the
    back at full height.

    LIBERO's two-layer shelf has its layers one above the other; the skills set things down from
    above, so each layer gets a third of the depth open to the sky (deep enough for a 16 cm frying pan)
    and the risers between them stay lower than a hand holding a book.
    """
    sx, sy, sz = scale(size, (0.57, 0.4, 0.2))
    c = rgba if rgba != (0.7, 0.7, 0.7, 1) else WOOD
    step = sx / 3
    links = [
        Link(
            "base",
            (
                box((0, -sy / 2 + T / 2, sz / 2), (sx, T, sz), c),
                box((0, sy / 2 - T / 2, sz / 2), (sx, T, sz), c),
            ),
            5.0,
        ),
    ]
    levels = (("bottom_region", -step, 0.0), ("top_region", 0.0, sz / 2), ("top_side", step, sz))
    for name, x, z in levels:
        # a board the width between the sides, and the riser under it down to the table
        shapes = [box((0, 0, -T / 2), (step, sy - 2 * T, T), c)]
        if z > T:
            shapes.append(box((0, 0, -z / 2), (step, sy - 2 * T, z - T), c))
        links.append(Link(name, tuple(shapes), 1.0, "base", Joint("fixed", (x, 0, max(z, T)))))
    return AssetModel(
        "shelf",
        links,
        part_links={name: name for name, _, _ in levels},
        fixed=True,
        extent=(sx, sy, sz),
    )


def make_table(size: Vec | None, rgba: RGBA) -> AssetModel:
    """The table: a slab whose top face is the asset's z = 0 plane (the base frame sits on the top)."""
    sx, sy, _ = scale(size, (1.2, 1.6, 0.05))
    return AssetModel(
        "table",
        [Link("base", (box((0, 0, -0.025), (sx, sy, 0.05), WOOD),), 0.0)],
        fixed=True,
        extent=(sx, sy, 0.05),
    )
