"""Packing into drawers and boxes: true footprints, the hand's room against the cabinet, capacity."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pybullet")


def test_a_mug_footprint_is_its_body_and_handle_not_a_symmetric_square() -> None:
    from gsr.skills.assets import make_asset
    from gsr.skills.packing import footprint

    mug = make_asset("mug", size=(0.044, 0.044, 0.05))
    centre, half = footprint(mug)
    # body 4.4 cm across; the handle sticks out 3 cm on +y only
    assert half[0] == pytest.approx(0.022, abs=0.002)
    assert 2 * half[1] == pytest.approx(0.074, abs=0.003)
    assert centre[1] == pytest.approx(0.015, abs=0.002) and abs(centre[0]) < 1e-6
    cube = make_asset("cube", size=(0.03, 0.03, 0.03))
    c, h = footprint(cube)
    assert np.allclose(c, 0, atol=1e-9) and np.allclose(h, 0.015, atol=1e-6)


def _drawer_world(level: str, cell: str, index: int, part: str):
    import pybullet as p
    from gsr.benchmarks.suites.gsr_bench_gen import generate_cell
    from gsr.skills.build import build_world

    task = generate_cell(cell, level, n=index + 1)[index]
    world = build_world(task, seed=0)
    oid, name = world.parts[part]
    cab = world.objects[oid]
    art = cab.model.articulations[name]
    p.resetJointState(cab.body, cab.links[art.link], art.open, physicsClientId=world.client)
    return world, cab


def _set_down(world, obj, spot: np.ndarray, delta: float, settle: int = 60) -> None:
    """Put ``obj`` turned by ``delta`` with its footprint centre at ``spot`` (as the place skill does),
    then let it settle for ``settle`` simulation steps."""
    import pybullet as p

    c = world.client
    _pos, q = p.getBasePositionAndOrientation(obj.body, physicsClientId=c)
    q2 = p.getQuaternionFromEuler((0, 0, p.getEulerFromQuaternion(q)[2] + delta))
    p.resetBasePositionAndOrientation(obj.body, (0, 0, 2), q2, physicsClientId=c)
    lo, hi = world.body_aabb(obj.body)
    base = np.array(
        [spot[0] - (lo[0] + hi[0]) / 2, spot[1] - (lo[1] + hi[1]) / 2, 2 + spot[2] + 0.003 - lo[2]]
    )
    p.resetBasePositionAndOrientation(obj.body, base.tolist(), q2, physicsClientId=c)
    if settle:
        world.step(settle)


@pytest.mark.physics
@pytest.mark.parametrize("index", [0, 10])
def test_six_gsr_bench_mugs_go_on_the_floor_of_a_drawer_with_the_hand_clear_of_the_cabinet(
    index: int,
) -> None:
    """GSR-Bench SOD General puts 5-6 mugs (4.4 cm, handle 3 cm) into one drawer of the short cabinet:
    all on the drawer's floor (no second layer), the hand's footprint at each release point clear of
    the carcass and the drawer above, the fingers' reach clear of the mugs already there."""
    import pybullet as p
    from gsr.skills.packing import HAND_HALF, finger_reach, packed_spot
    from gsr.skills.sim_graph import support_of

    world, cab = _drawer_world(
        "General", "Semantic Object Disambiguation", index, "short_cabinet/drawer_middle"
    )
    try:
        target = "short_cabinet/drawer_middle"
        mugs = [o for o in world.objects.values() if o.id.startswith("red_mug")]
        assert len(mugs) == 6
        for finger in world.robot.fingers:  # the fingers closed on a 4.4 cm mug
            p.resetJointState(world.robot.body, finger, 0.022, physicsClientId=world.client)
        interior = cab.model.interiors["drawer_1"]
        floor = world.to_world(cab.body, cab.links["drawer_1"], interior.center)[2] - interior.size[2] / 2
        front = world.aabb(cab.body, -1)[0][0]  # the carcass front (the drawer opens towards -x)
        for mug in mugs:
            closing = world.yaw_of(mug.body)  # a small mug is held closing across its body (local x)
            spot, delta = packed_spot(world, mug, target, closing)
            assert spot[2] == pytest.approx(floor, abs=1e-6), f"{mug.id} set on a second layer"
            assert finger_reach(world) < 0.07
            _set_down(world, mug, spot, delta)
            # the hand (long along the closing axis, centred on the mug's body where it holds it) stays
            # before the carcass front: it would meet the closed drawer above
            e1 = closing + delta
            reach_x = abs(math.cos(e1)) * HAND_HALF[0] + abs(math.sin(e1)) * HAND_HALF[1]
            assert world.link_pose(mug.body, -1)[0][0] + reach_x <= front + 1e-3, mug.id
            assert support_of(world, mug.id) == ("in", target), mug.id
    finally:
        world.close()


@pytest.mark.physics
def test_cubes_fill_a_gsr_bench_box_in_rows_from_the_near_wall() -> None:
    """Eight 3 cm cubes into a 17 x 25 cm GSR-Bench box: all on its floor, the first one at the wall
    nearest the robot (the easiest to reach)."""
    import pybullet as p
    from gsr.benchmarks.suites.gsr_bench_gen import generate_cell
    from gsr.skills.build import build_world
    from gsr.skills.packing import packed_spot
    from gsr.skills.sim_graph import support_of

    task = generate_cell("Semantic Object Disambiguation", "Simple", n=1)[0]
    world = build_world(task, seed=0)
    try:
        box = next(o for o in world.objects.values() if o.model.name == "box")
        cubes = [o for o in world.objects.values() if o.model.name == "cube"][:8]
        box_lo, box_hi = world.body_aabb(box.body)
        for finger in world.robot.fingers:  # the fingers closed on a 3 cm cube
            p.resetJointState(world.robot.body, finger, 0.015, physicsClientId=world.client)
        first = None
        for cube in cubes:
            spot, delta = packed_spot(world, cube, box.id, world.yaw_of(cube.body))
            assert spot[2] < box_lo[2] + 0.02, f"{cube.id} set on a second layer"
            first = spot if first is None else first
            _set_down(world, cube, spot, delta)
            assert support_of(world, cube.id) == ("in", box.id), cube.id
        # the first cube went to the near side (towards the robot, which stands at -x)
        assert first[0] < (box_lo[0] + box_hi[0]) / 2
    finally:
        world.close()


@pytest.mark.physics
def test_six_mugs_held_as_an_episode_held_them_all_go_on_the_drawer_floor() -> None:
    """SOD General 10's six mugs into ``drawer_middle``, each held as the episode held it (arm, fingers
    and mug saved at each packing, seed 0: the second taken 30 deg aslant, the fifth gripped 5 mm wider),
    every earlier mug put exactly at its packed spot (not settled). The look-ahead counted the room left for
    further mugs held like the current one, so the aslant and the wide grip each spent it on a layout
    no later mug could use: the sixth had no floor spot and went on a mug (not ``in``)."""
    import json

    import pybullet as p
    from gsr.skills.packing import packed_spot

    from tests.skills.conftest import SNAPSHOTS

    saved = json.loads((SNAPSHOTS / "sod_general_10_mug_grasps.json").read_text())
    target = saved["target"]
    world, cab = _drawer_world("General", "Semantic Object Disambiguation", 10, target)
    try:
        c = world.client
        # the drawer as far out as the episode opened it (1 cm past its nominal open position)
        art = cab.model.articulations[world.parts[target][1]]
        p.resetJointState(cab.body, cab.links[art.link], saved["drawer_joint"], physicsClientId=c)
        interior = cab.model.interiors["drawer_1"]
        floor = world.to_world(cab.body, cab.links["drawer_1"], interior.center)[2] - interior.size[2] / 2
        placed: dict[str, tuple] = {}
        for g in saved["grasps"]:
            world.robot.reset(g["arm"])
            for finger, width in zip(world.robot.fingers, g["fingers"], strict=True):
                p.resetJointState(world.robot.body, finger, width, physicsClientId=c)
            for oid, (pos, q) in placed.items():  # the earlier mugs where they were set down
                p.resetBasePositionAndOrientation(world.objects[oid].body, pos, q, physicsClientId=c)
            mug = world.objects[g["object"]]
            p.resetBasePositionAndOrientation(mug.body, g["position"], g["orientation"], physicsClientId=c)
            spot, delta = packed_spot(world, mug, target, g["closing_yaw"])
            assert spot[2] == pytest.approx(floor, abs=1e-6), f"{mug.id} set on a second layer"
            _set_down(world, mug, spot, delta, settle=0)
            placed[mug.id] = p.getBasePositionAndOrientation(mug.body, physicsClientId=c)
    finally:
        world.close()
