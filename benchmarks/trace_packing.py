"""Trace the packing of one generated GSR-Bench task: where each object goes, what is already there.

``python -m gsr.benchmarks.trace_packing gsrgen_sod_general_14`` runs the task as ``bench_skills --suite
gsr-bench-gen`` does (planner agent given the goal, seed 0, bounded recovery) and prints, for every
spot the packing chooses in a container, the spot in the container's own frame (u towards the
cabinet's back for a drawer), its height above the floor (> 0: a second layer), the wrist turn, and
every object in or by the container with its position, tilt and support; and, around every release of
the fingers, the tilt of the objects under the hand. The failure-cause tables of docs/skills.md were
read from this output.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from gsr.benchmarks.bench_skills import EPISODE_CPU_S, RETRIES, run_suite_task
from gsr.benchmarks.suites import get_suite
from gsr.skills import motion, packing
from gsr.skills.packing import container_of
from gsr.skills.sim_graph import support_of

if TYPE_CHECKING:
    from gsr.skills.world import World


def tilt_deg(world: World, body: int) -> float:
    """How far (degrees) a body's up axis leans from the vertical."""
    import pybullet as p

    _pos, q = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
    up = np.array(p.getMatrixFromQuaternion(q)).reshape(3, 3)[:, 2]
    return float(np.degrees(np.arccos(np.clip(up[2], -1.0, 1.0))))


def container_contents(world: World, target: str, skip: str = "") -> list[dict]:
    """Every movable object over ``target``'s interior (5 cm round it), in the container's frame:
    ``{"id", "uv", "yaw" (degrees off the container's axes, -45..45), "bottom" (above the floor),
    "height", "tilt", "support"}``."""

    found = container_of(world, target)
    if found is None:
        return []
    cont, interior, link, _drawer = found
    yaw = world.yaw_of(cont.body, link)
    centre = world.to_world(cont.body, link, interior.center)
    floor = centre[2] - interior.size[2] / 2
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    rows = []
    for o in world.objects.values():
        if o.id == skip or o.model.fixed:
            continue
        lo, hi = world.body_aabb(o.body)
        uv = rot.T @ ((lo[:2] + hi[:2]) / 2 - centre[:2])
        if np.any(np.abs(uv) > np.array(interior.size[:2]) / 2 + 0.05):
            continue
        rows.append(
            {
                "id": o.id,
                "uv": [round(float(x), 3) for x in uv],
                "yaw": round(
                    math.degrees((world.yaw_of(o.body) - yaw + math.pi / 4) % (math.pi / 2) - math.pi / 4), 1
                ),
                "bottom": round(float(lo[2] - floor), 3),
                "height": round(float(hi[2] - lo[2]), 3),
                "tilt": round(tilt_deg(world, o.body), 1),
                "support": list(support_of(world, o.id) or ()),
            }
        )
    return rows


def spot_in_frame(world: World, target: str, spot: np.ndarray) -> tuple[list[float], float]:
    """A packed spot (world x, y, bottom z) as ``(uv, height above the floor)`` in ``target``'s frame."""

    cont, interior, link, _drawer = container_of(world, target)
    yaw = world.yaw_of(cont.body, link)
    centre = world.to_world(cont.body, link, interior.center)
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    uv = rot.T @ (np.asarray(spot[:2]) - centre[:2])
    return [round(float(x), 3) for x in uv], round(float(spot[2] - (centre[2] - interior.size[2] / 2)), 3)


def trace(task_id: str, out=sys.stdout, snapshots: Path | None = None) -> dict:
    """Run ``task_id`` with the packing and every finger release traced to ``out``; the episode record.
    ``snapshots``: a folder to save the PyBullet state in (``p.saveBullet``) each time a spot is
    packed, as ``<object>_<n>.bullet`` (n counts the spots packed so far), before the spot is chosen."""

    tasks = {t.id: t for t in get_suite("gsr-bench-gen").tasks(None, 0)}
    if task_id not in tasks:
        raise SystemExit(f"error: no generated task {task_id!r}")
    packed, gripper = packing.packed_spot, motion.Motion.gripper
    spots: dict[str, list[float]] = {}  # the latest packed spot of each object, in its container's frame
    calls = [0]

    def traced_spot(world, obj, target, closing_yaw):
        if snapshots is not None:
            import pybullet as p

            snapshots.mkdir(parents=True, exist_ok=True)
            name = snapshots / f"{obj.id}_{calls[0]}.bullet"
            p.saveBullet(str(name), physicsClientId=world.client)
            print(f"SAVED {name} (closing yaw {closing_yaw:.4f})", file=out)
        calls[0] += 1
        res = packed(world, obj, target, closing_yaw)
        if res is not None:
            uv, z = spot_in_frame(world, target, res[0])
            spots[obj.id] = uv
            print(f"PACK {obj.id} -> {target}: uv {uv} above floor {z} turn {res[1]:.2f}", file=out)
            for row in container_contents(world, target, skip=obj.id):
                if row["id"] in spots:  # where it ended against where it was packed (mm)
                    row["off_mm"] = [
                        round(1000 * (a - b)) for a, b in zip(row["uv"], spots[row["id"]], strict=True)
                    ]
                print(f"    {json.dumps(row)}", file=out)
        return res

    def traced_gripper(self, width, *a, **k):
        ee = self.pose()[0]
        near = [o for o in self.world.objects.values() if not o.model.fixed]
        near = [o for o in near if np.linalg.norm(self.world.link_pose(o.body, -1)[0][:2] - ee[:2]) < 0.08]
        before = {o.id: tilt_deg(self.world, o.body) for o in near}
        r = gripper(self, width, *a, **k)
        for o in near:
            print(
                f"GRIPPER {width:.3f}: {o.id} tilt {before[o.id]:.1f} -> {tilt_deg(self.world, o.body):.1f}",
                file=out,
            )
        return r

    packing.packed_spot, motion.Motion.gripper = traced_spot, traced_gripper
    try:
        r = run_suite_task((tasks[task_id].model_dump(mode="json"), 0, RETRIES, EPISODE_CPU_S))
    finally:
        packing.packed_spot, motion.Motion.gripper = packed, gripper
    return r


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("task", help="a gsr-bench-gen task id, e.g. gsrgen_sod_general_14")
    ap.add_argument("--snapshots", type=Path, help="save the PyBullet state at every packed spot here")
    args = ap.parse_args(argv)
    r = trace(args.task, snapshots=args.snapshots)
    print(json.dumps({k: r[k] for k in ("id", "success", "steps", "wall_s", "cpu_s", "reason")}))
    return 0 if r["success"] else 1


if __name__ == "__main__":
    sys.exit(main())
