"""The packing trace (benchmarks/trace_packing.py) reports spots and contents in the container's frame."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")


@pytest.mark.physics
def test_contents_of_a_drawer_in_its_own_frame_with_tilt_and_support() -> None:
    import pybullet as p
    from gsr.benchmarks.suites.gsr_bench_gen import generate_cell
    from gsr.benchmarks.trace_packing import container_contents, spot_in_frame
    from gsr.skills.build import build_world
    from gsr.skills.packing import packed_spot

    target = "short_cabinet/drawer_middle"
    world = build_world(generate_cell("Semantic Object Disambiguation", "General", n=1)[0], seed=0)
    oid, name = world.parts[target]
    cab = world.objects[oid]
    art = cab.model.articulations[name]
    p.resetJointState(cab.body, cab.links[art.link], art.open, physicsClientId=world.client)
    try:
        mug, other = [o for o in world.objects.values() if o.id.startswith("red_mug")][:2]
        spot, delta = packed_spot(world, mug, target, world.yaw_of(mug.body))
        uv, above = spot_in_frame(world, target, spot)
        assert above == pytest.approx(0.0, abs=1e-6)  # on the floor, not a second layer
        # set down turned by delta with its footprint's centre at the spot (as the place skill does)
        _pos, q = p.getBasePositionAndOrientation(mug.body, physicsClientId=world.client)
        q = p.getQuaternionFromEuler((0, 0, p.getEulerFromQuaternion(q)[2] + delta))
        p.resetBasePositionAndOrientation(mug.body, (0, 0, 2), q, physicsClientId=world.client)
        lo, hi = world.body_aabb(mug.body)
        base = [spot[0] - (lo[0] + hi[0]) / 2, spot[1] - (lo[1] + hi[1]) / 2, 2 + spot[2] + 0.003 - lo[2]]
        p.resetBasePositionAndOrientation(mug.body, base, q, physicsClientId=world.client)
        world.step(60)
        rows = {r["id"]: r for r in container_contents(world, target)}
        assert other.id not in rows  # still on the table, far from the drawer
        row = rows[mug.id]
        assert row["support"] == ["in", target] and row["tilt"] < 5.0
        assert abs(row["yaw"]) < 2.0  # the wrist's turn lined it up with the drawer's walls
        # the footprint's centre where the packing put it (the box of a mug with its handle)
        assert np.allclose(row["uv"], uv, atol=0.01)
        # a mug laid on its side reads as tilted
        pos, _q = p.getBasePositionAndOrientation(mug.body, physicsClientId=world.client)
        p.resetBasePositionAndOrientation(
            mug.body, pos, p.getQuaternionFromEuler((1.5708, 0, 0)), physicsClientId=world.client
        )
        assert {r["id"]: r for r in container_contents(world, target)}[mug.id]["tilt"] > 80.0
    finally:
        world.close()
