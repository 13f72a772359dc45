"""Shared pieces of the procedural assets: palette, materials, wall thickness and compound shapes."""

from __future__ import annotations

import math

from gsr.skills.urdf import RGBA, Shape, Vec, box

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


def scale(size: Vec | None, default: Vec) -> Vec:
    """The requested size, or the asset's default."""
    return tuple(default) if size is None else tuple(float(v) for v in size)  # type: ignore[return-value]


def ring(radius: float, height: float, rgba: RGBA, z0: float = 0.0, n: int = 14) -> list[Shape]:
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


def open_box(sx: float, sy: float, sz: float, rgba: RGBA, z0: float = 0.0) -> list[Shape]:
    """Floor and four walls of an open box of outer extents (sx, sy, sz) standing at z0."""
    return [
        box((0, 0, z0 + T / 2), (sx, sy, T), rgba),
        box((-sx / 2 + T / 2, 0, z0 + sz / 2), (T, sy, sz), rgba),
        box((sx / 2 - T / 2, 0, z0 + sz / 2), (T, sy, sz), rgba),
        box((0, -sy / 2 + T / 2, z0 + sz / 2), (sx - 2 * T, T, sz), rgba),
        box((0, sy / 2 - T / 2, z0 + sz / 2), (sx - 2 * T, T, sz), rgba),
    ]
