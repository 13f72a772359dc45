"""A small URDF writer: links made of boxes and cylinders, joined by fixed, prismatic or revolute joints.

Procedural assets (``gsr.skills.assets``) describe each object as :class:`Link` objects; :func:`urdf_text`
turns them into URDF text that PyBullet loads. Everything is primitives, so collision shapes are exact
and loading is fast.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

Vec = tuple[float, float, float]
RGBA = tuple[float, float, float, float]


@dataclass(frozen=True, slots=True)
class Shape:
    """One box (``size`` = full extents) or cylinder (``size`` = radius, radius, length) at ``xyz``."""

    kind: str  # "box" | "cylinder"
    xyz: Vec
    size: Vec
    rgba: RGBA = (0.7, 0.7, 0.7, 1.0)
    rpy: Vec = (0.0, 0.0, 0.0)
    collide: bool = True


@dataclass(frozen=True, slots=True)
class Joint:
    """How a link attaches to its parent: type, origin in the parent frame, axis and limits."""

    type: str  # "fixed" | "prismatic" | "revolute"
    xyz: Vec = (0.0, 0.0, 0.0)
    axis: Vec = (1.0, 0.0, 0.0)
    lower: float = 0.0
    upper: float = 0.0
    damping: float = 1.0
    friction: float = 0.05


@dataclass(frozen=True, slots=True)
class Link:
    """A rigid link: its shapes (in the link frame), mass, parent and joint (none for the base)."""

    name: str
    shapes: tuple[Shape, ...]
    mass: float
    parent: str | None = None
    joint: Joint | None = None
    friction: float = 1.0
    extra: dict[str, object] = field(default_factory=dict)


def box(xyz: Vec, size: Vec, rgba: RGBA, collide: bool = True) -> Shape:
    """A box shape with full extents ``size`` centred at ``xyz``."""
    return Shape("box", xyz, size, rgba, collide=collide)


def cylinder(xyz: Vec, radius: float, length: float, rgba: RGBA) -> Shape:
    """A z-axis cylinder centred at ``xyz``."""
    return Shape("cylinder", xyz, (radius, radius, length), rgba)


def _f(v: float) -> str:
    return f"{v:.6g}"


def _v(v: Vec) -> str:
    return " ".join(_f(x) for x in v)


def _geometry(s: Shape) -> str:
    if s.kind == "box":
        return f'<box size="{_v(s.size)}"/>'
    return f'<cylinder radius="{_f(s.size[0])}" length="{_f(s.size[2])}"/>'


def _extent(s: Shape, i: int) -> float:
    return s.size[i] if s.kind == "box" or i == 2 else 2 * s.size[i]


def volume(s: Shape) -> float:
    """The shape's volume in cubic metres (a box's extents' product, a cylinder's pi r^2 l)."""
    if s.kind == "box":
        return s.size[0] * s.size[1] * s.size[2]
    return math.pi * s.size[0] * s.size[1] * s.size[2]


def centre_of_mass(link: Link) -> Vec:
    """The link's centre of mass in its frame: its solid shapes' centres weighted by their volumes.

    Uniform density over the shapes that collide (visual-only shapes weigh nothing, unless a link has no
    other). A mug's handle or a box's thin walls no longer pull the centre to the middle of the bounding box:
    a 4.4 cm mug with a 3 cm handle had its centre 1.5 cm towards the handle and tipped onto it at 15.6 deg.
    """
    solid = [s for s in link.shapes if s.collide] or list(link.shapes)
    weights = [volume(s) for s in solid]
    total = sum(weights)
    if total <= 0.0:
        return tuple(sum(s.xyz[i] for s in solid) / len(solid) for i in range(3))  # type: ignore[return-value]
    return tuple(sum(w * s.xyz[i] for w, s in zip(weights, solid, strict=True)) / total for i in range(3))  # type: ignore[return-value]


def _inertia(link: Link) -> str:
    # the centre of mass from the solid shapes' volumes; the inertia a solid-box approximation over the
    # shapes' bounding box: plausible, positive definite
    lo = [min(s.xyz[i] - _extent(s, i) / 2 for s in link.shapes) for i in range(3)]
    hi = [max(s.xyz[i] + _extent(s, i) / 2 for s in link.shapes) for i in range(3)]
    dx, dy, dz = (max(hi[i] - lo[i], 0.01) for i in range(3))
    com = centre_of_mass(link)
    m = link.mass
    ixx, iyy, izz = m * (dy * dy + dz * dz) / 12, m * (dx * dx + dz * dz) / 12, m * (dx * dx + dy * dy) / 12
    return (
        f'<inertial><origin xyz="{_v(com)}"/><mass value="{_f(m)}"/>'
        f'<inertia ixx="{_f(ixx)}" iyy="{_f(iyy)}" izz="{_f(izz)}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _link(link: Link) -> str:
    # material names must be unique in the whole URDF (link names are): PyBullet's URDF reader keeps one
    # colour per material name, so per-link names m0, m1... gave every link's first visual one link's colour
    parts = [f'<link name="{link.name}">', _inertia(link)]
    for i, s in enumerate(link.shapes):
        origin = f'<origin xyz="{_v(s.xyz)}" rpy="{_v(s.rpy)}"/>'
        parts.append(
            f'<visual name="v{i}">{origin}<geometry>{_geometry(s)}</geometry>'
            f'<material name="{link.name}_m{i}"><color rgba="{_v(s.rgba[:3])} {_f(s.rgba[3])}"/></material>'
            "</visual>"
        )
        if s.collide:
            parts.append(f'<collision name="c{i}">{origin}<geometry>{_geometry(s)}</geometry></collision>')
    parts.append(
        f'<contact><lateral_friction value="{_f(link.friction)}"/><rolling_friction value="0.001"/>'
        '<spinning_friction value="0.002"/></contact>'
    )
    parts.append("</link>")
    return "\n".join(parts)


def _joint(link: Link) -> str:
    j = link.joint
    assert j is not None and link.parent is not None
    limit = ""
    if j.type in ("prismatic", "revolute"):
        limit = (
            f'<limit lower="{_f(j.lower)}" upper="{_f(j.upper)}" effort="100" velocity="1"/>'
            f'<dynamics damping="{_f(j.damping)}" friction="{_f(j.friction)}"/>'
        )
    return (
        f'<joint name="{link.name}_joint" type="{j.type}"><parent link="{link.parent}"/>'
        f'<child link="{link.name}"/><origin xyz="{_v(j.xyz)}" rpy="0 0 0"/>'
        f'<axis xyz="{_v(j.axis)}"/>{limit}</joint>'
    )


def urdf_text(name: str, links: list[Link]) -> str:
    """URDF text for a robot ``name`` made of ``links`` (the first is the base)."""
    if not links or links[0].parent is not None:
        raise ValueError(f"asset {name!r}: the first link must be the base (no parent)")
    body = [_link(link) for link in links]
    body += [_joint(link) for link in links[1:]]
    # one element per line: PyBullet's XML reader fails on some very long lines
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(body) + "\n</robot>\n"
