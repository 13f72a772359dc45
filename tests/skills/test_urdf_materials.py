"""The URDF writer's materials: every link of a multi-link asset keeps its own colour in PyBullet.

PyBullet's URDF reader keeps one colour per material name in a file; the writer once named materials
m0, m1... per link, so the names repeated across links and a microwave's grey carcass rendered green.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest

pybullet = pytest.importorskip("pybullet")

from gsr.skills.assets import BUILDERS, asset_urdf_path, make_asset  # noqa: E402
from gsr.skills.urdf import Joint, Link, box, urdf_text  # noqa: E402

GREY = (0.5, 0.5, 0.5, 1.0)
GREEN = (0.1, 0.8, 0.1, 1.0)


@pytest.fixture
def client():
    """A headless PyBullet client of its own."""
    c = pybullet.connect(pybullet.DIRECT)
    yield c
    pybullet.disconnect(c)


def _load(client: int, path: Path, fixed: bool = True) -> int:
    return pybullet.loadURDF(str(path), useFixedBase=fixed, physicsClientId=client)


def _two_link_urdf(tmp: Path) -> Path:
    # a grey block with a green block on top: each link's first (only) visual
    links = [
        Link("carcass", (box((0, 0, 0.05), (0.2, 0.2, 0.1), GREY),), 1.0),
        Link(
            "knob",
            (box((0, 0, 0), (0.1, 0.1, 0.05), GREEN),),
            0.2,
            parent="carcass",
            joint=Joint("fixed", (0, 0, 0.125)),
        ),
    ]
    path = tmp / "two_links.urdf"
    path.write_text(urdf_text("two_links", links), encoding="utf-8")
    return path


def test_material_names_are_unique_in_a_urdf() -> None:
    for kind in sorted(BUILDERS):
        model = make_asset(kind)
        text = urdf_text(model.name, model.links)
        names = [line.split('<material name="', 1)[1].split('"', 1)[0] for line in text.split("<visual")[1:]]
        assert len(names) == sum(len(link.shapes) for link in model.links)
        assert len(set(names)) == len(names), kind


def test_each_link_keeps_its_own_colour_in_visual_shape_data(client: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        body = _load(client, _two_link_urdf(Path(tmp)))
    colours = {v[1]: tuple(v[7]) for v in pybullet.getVisualShapeData(body, physicsClientId=client)}
    assert colours[-1] == pytest.approx(GREY)
    assert colours[0] == pytest.approx(GREEN)


def test_each_link_renders_in_its_own_colour(client: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        body = _load(client, _two_link_urdf(Path(tmp)))
    view = pybullet.computeViewMatrix((0.45, 0.0, 0.35), (0.0, 0.0, 0.07), (0, 0, 1))
    proj = pybullet.computeProjectionMatrixFOV(45, 1.0, 0.05, 3.0)
    _, _, rgb, _, seg = pybullet.getCameraImage(
        96,
        96,
        view,
        proj,
        renderer=pybullet.ER_TINY_RENDERER,
        flags=pybullet.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
        physicsClientId=client,
    )
    rgb = np.reshape(np.asarray(rgb, dtype=np.uint8), (96, 96, 4))[..., :3].astype(float)
    seg = np.reshape(np.asarray(seg), (96, 96))
    on_body = (seg >= 0) & ((seg & ((1 << 24) - 1)) == body)
    link = (seg >> 24) - 1
    base = rgb[on_body & (link == -1)]
    top = rgb[on_body & (link == 0)]
    assert len(base) > 50 and len(top) > 20
    # the grey carcass is grey (no channel stands out), the knob green
    r, g, b = np.median(base, axis=0)
    assert abs(g - r) < 10 and abs(g - b) < 10, (r, g, b)
    r, g, b = np.median(top, axis=0)
    assert g > r + 60 and g > b + 60, (r, g, b)


@pytest.mark.parametrize("kind", sorted(BUILDERS))
def test_every_asset_link_shows_its_declared_colours(client: int, kind: str) -> None:
    model = make_asset(kind)
    body = _load(client, asset_urdf_path(model), model.fixed)
    shown: dict[int, list[tuple[float, ...]]] = {}
    for v in pybullet.getVisualShapeData(body, physicsClientId=client):
        shown.setdefault(v[1], []).append(tuple(round(c, 4) for c in v[7]))
    for index, link in enumerate(model.links):
        declared = [tuple(round(float(f"{c:.6g}"), 4) for c in s.rgba) for s in link.shapes]
        assert shown.get(index - 1, []) == declared, (kind, link.name)
