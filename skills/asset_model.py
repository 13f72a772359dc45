"""What an asset is besides its URDF: grasp sites, handles, articulations, interiors and surfaces.

Every procedural asset (``gsr.skills.assets``) has its base frame at the bottom centre, its front facing
local -x (towards a robot that looks along +x) and is described in that frame. Parts are named
generically (``drawer_0`` is the bottom drawer, ``top_side``, ``lid``, ``knob``, ``door``, ``button``,
``switch``, ``burner``, ``compartment_front``); the world maps scene-graph part nodes onto them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from gsr.skills.urdf import Link, Vec


@dataclass(frozen=True, slots=True)
class GraspSite:
    """Where to grasp: a point (link frame), the approach (``down`` or ``front``) and the finger closing axis.

    ``yaw`` is the direction (radians, link frame, about z) along which the fingers close for a top-down
    grasp; for a ``front`` approach the fingers close vertically and ``yaw`` is the pointing direction.
    ``width`` is the object's extent between the fingers.
    """

    link: str
    xyz: Vec
    yaw: float = 0.0
    approach: str = "down"
    width: float = 0.04


@dataclass(frozen=True, slots=True)
class Articulation:
    """A movable part: its link, kind and joint positions meaning closed/off and open/on."""

    link: str
    kind: str  # "drawer" | "lid" | "door" | "knob" | "button"
    closed: float
    open: float
    handle: GraspSite | None = None

    def is_open(self, q: float) -> bool:
        """True when joint position ``q`` is past the middle of the closed..open travel."""
        return (q - self.closed) / (self.open - self.closed) > 0.5


@dataclass(frozen=True, slots=True)
class Interior:
    """A containment volume (link frame box): what lies >= 50% inside is ``in`` the part."""

    link: str
    center: Vec
    size: Vec


@dataclass
class AssetModel:
    """A procedural asset: URDF links plus the semantics skills and ground truth need."""

    name: str
    links: list[Link]
    grasps: list[GraspSite] = field(default_factory=list)
    articulations: dict[str, Articulation] = field(default_factory=dict)
    interiors: dict[str, Interior] = field(default_factory=dict)
    #: part name -> link name for parts that are plain links (top_side, burner, compartments)
    part_links: dict[str, str] = field(default_factory=dict)
    #: which articulated part ``open``/``close`` and ``turn_on``/``turn_off`` of the whole object use
    open_part: str | None = None
    switch_part: str | None = None
    #: keypoints (name -> link, xyz) exposed in the scene graph (mug handle, drawer pulls)
    keypoints: dict[str, tuple[str, Vec]] = field(default_factory=dict)
    extent: Vec = (0.05, 0.05, 0.05)
    fixed: bool = False

    def link_names(self) -> list[str]:
        """Link names in URDF order (index = PyBullet link index + 1; the base is -1)."""
        return [link.name for link in self.links]
