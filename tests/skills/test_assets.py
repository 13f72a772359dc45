"""Procedural assets: every builder's URDF loads in PyBullet, links and semantics are consistent."""

from __future__ import annotations

import pytest

pybullet = pytest.importorskip("pybullet")

from gsr.skills.assets import BUILDERS, asset_category, asset_urdf_path, default_color, make_asset  # noqa: E402


@pytest.fixture(scope="module")
def client():
    """A headless PyBullet client for the module."""
    c = pybullet.connect(pybullet.DIRECT)
    yield c
    pybullet.disconnect(c)


@pytest.mark.parametrize("kind", sorted(BUILDERS))
def test_asset_loads_with_declared_links(client: int, kind: str) -> None:
    model = make_asset(kind)
    body = pybullet.loadURDF(str(asset_urdf_path(model)), useFixedBase=model.fixed, physicsClientId=client)
    names = [
        pybullet.getJointInfo(body, j, physicsClientId=client)[12].decode()
        for j in range(pybullet.getNumJoints(body, physicsClientId=client))
    ]
    assert names == model.link_names()[1:]
    declared = {a.link for a in model.articulations.values()} | {i.link for i in model.interiors.values()}
    declared |= set(model.part_links.values()) | {g.link for g in model.grasps}
    assert declared <= set(model.link_names())
    lo, hi = pybullet.getAABB(body, -1, physicsClientId=client)
    assert hi[2] > lo[2] and hi[0] > lo[0]


def test_urdf_cache_is_content_addressed() -> None:
    a = asset_urdf_path(make_asset("cube", (0.05, 0.05, 0.05), "red"))
    b = asset_urdf_path(make_asset("cube", (0.05, 0.05, 0.05), "red"))
    c = asset_urdf_path(make_asset("cube", (0.05, 0.05, 0.05), "blue"))
    assert a == b and a != c
    assert 'rgba="0.85 0.1 0.1 1"' in a.read_text()


def test_asset_names_resolve_through_the_category_registry() -> None:
    assert asset_category("akita_black_bowl") == "bowl"
    assert asset_category("wooden_cabinet") == "cabinet"
    assert asset_category("box_with_lid") == "lidded_box"
    assert asset_category("no_such_thing_at_all") == "thing"
    assert default_color("akita_black_bowl") == "black"


def test_graspable_objects_fit_the_gripper() -> None:
    # the Panda opens 8 cm: every grasp site must leave room for the fingers
    for kind in BUILDERS:
        for site in make_asset(kind).grasps:
            assert site.width <= 0.07, (kind, site)


def test_cabinet_has_three_drawers_with_handles_and_interiors() -> None:
    cab = make_asset("cabinet")
    drawers = sorted(p for p in cab.articulations if p.startswith("drawer_"))
    assert drawers == ["drawer_0", "drawer_1", "drawer_2"]
    for d in drawers:
        assert cab.articulations[d].handle is not None
        assert d in cab.interiors
        assert f"{d}/handle" in cab.keypoints


def test_a_mug_stands_back_up_from_a_lean_towards_its_handle() -> None:
    """The centre of mass comes from the shapes' volumes, not their bounding box (the handle weighs little).

    GSR-Bench's 4.4 cm mug with its centre in the bounding box's middle (1.5 cm towards the handle) tips onto
    the handle from a 15.6 deg lean: let go at 20 deg in a drawer, it lay on its side.
    """
    import math

    from gsr.skills.urdf import centre_of_mass

    model = make_asset("mug", (0.044, 0.044, 0.05), "red")
    com = centre_of_mass(model.links[0])
    assert abs(com[0]) < 1e-9 and 0.0 < com[1] < 0.022 / 3  # the handle pulls it, a little
    client = pybullet.connect(pybullet.DIRECT)  # its own world: the module's client holds every asset
    try:
        plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client)
        pybullet.createMultiBody(0, plane, physicsClientId=client)
        pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
        lean = math.radians(20)  # about x: the top towards +y, the handle's side
        body = pybullet.loadURDF(
            str(asset_urdf_path(model)),
            basePosition=(0, 0, 0.004),
            baseOrientation=pybullet.getQuaternionFromEuler((-lean, 0, 0)),
            physicsClientId=client,
        )
        for _ in range(480):
            pybullet.stepSimulation(physicsClientId=client)
        roll, pitch, _ = pybullet.getEulerFromQuaternion(
            pybullet.getBasePositionAndOrientation(body, physicsClientId=client)[1]
        )
        assert math.degrees(math.hypot(roll, pitch)) < 5.0  # upright again, not on its handle
    finally:
        pybullet.disconnect(client)
