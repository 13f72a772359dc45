"""Collision-checked arm motion: Cartesian waypoints -> IK configurations -> checked, tracked joint motion.

Every straight segment is interpolated at 1 cm, solved by IK seeded from the previous configuration
(so the path is continuous), and each configuration is checked against the world with
``getClosestPoints`` before anything moves. Execution drives the joints with position control inside a
step budget; nothing here teleports objects or welds them to the hand.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence

import numpy as np
from gsr.skills.result import Failure, SkillError
from gsr.skills.robot import ARM_FRONT, ARM_HOME, GRIPPER
from gsr.skills.world import World

Pose = tuple[np.ndarray, tuple[float, float, float, float]]
RESOLUTION = 0.01  # m between interpolated waypoints
STEPS_PER_WAYPOINT = 6  # 240 Hz: about 0.4 m/s
#: How far in front of a target (in x) the base parks: top-down reach is best around half a metre.
STANDOFF = 0.5
POS_TOL, ANG_TOL = 0.008, 0.08
MAX_JOINT_JUMP = 0.5  # rad between consecutive 1 cm waypoints: more is an IK branch flip, not a motion
JOINT_STEP = 0.03  # rad per waypoint of a joint-space move
#: How far back (m) a base route is looked for with the arm's clearance checked on every leg.
ROUTE_BACK_ARM = 0.2


def _link_name(robot, link: int) -> str:
    """A robot link in words for diagnoses: ``hand``, ``left finger``, ``link7``, ``base rail``."""
    import pybullet as p

    if link < 0:
        return "base rail"
    name = p.getJointInfo(robot.body, link, physicsClientId=robot.client)[12].decode()
    name = (
        name.removeprefix("panda_")
        .replace("leftfinger", "left finger")
        .replace("rightfinger", "right finger")
    )
    return {"carriage": "base rail", "link0": "arm base"}.get(name, name)


class Motion:
    """Plans and executes checked arm motions in one world; counts the simulation steps it uses."""

    def __init__(self, world: World, budget: int = 12000) -> None:
        self.world = world
        self.robot = world.robot
        self.budget = budget
        self.used = 0
        self.ignore: set[int] = set()  # bodies the arm may touch (the object being grasped or held)
        self.ignore_links: set[tuple[int, int]] = set()
        self.held: int | None = None
        #: carrying something loose (a box with a cube in it): the targets move on every simulation step
        self.gentle = False
        #: configurations :meth:`plan_base` checked with ``path`` (its first pose first), or None
        self.planned_path: list[np.ndarray] | None = None

    # ------------------------------------------------------------ planning

    def solve(self, pos: np.ndarray, quat: Sequence[float], seed: np.ndarray | None = None) -> np.ndarray:
        """An IK configuration for the grasp point at ``pos`` / ``quat`` with the base where it is now."""
        base = self.robot.q()[:2]
        seeds = [s for s in (seed, self.robot.q()) if s is not None]
        seeds += [np.array((*base, *ARM_HOME)), np.array((*base, *ARM_FRONT))]
        _best, best_err = None, math.inf
        for s in seeds:
            q = self.robot.ik(np.asarray(pos), quat, base, seed=s)
            dp, da = self.robot.fk_error(q, np.asarray(pos), quat)
            if dp < POS_TOL and da < ANG_TOL:
                return q
            if dp + da * 0.1 < best_err:
                _best, best_err = q, dp + da * 0.1
        raise SkillError(
            Failure.UNREACHABLE, f"no IK solution at {np.round(pos, 3).tolist()} (best error {best_err:.3f})"
        )

    def collision(self, q: np.ndarray, margin: float = 0.0) -> str | None:
        """The first obstacle the arm at ``q`` would touch (closer than ``margin``), or None."""
        hit = self.first_hit(q, margin)
        return hit[0] if hit else None

    def first_hit(self, q: np.ndarray, margin: float = 0.0) -> tuple[str, int] | None:
        """``(what, robot link)`` of the first obstacle the arm at ``q`` would touch, or None."""
        import pybullet as p

        w, r = self.world, self.robot
        with r.probe():
            r.reset(q)
            for o in w.objects.values():
                if o.body in self.ignore:
                    continue
                for pt in p.getClosestPoints(r.body, o.body, margin, physicsClientId=w.client):
                    if (o.body, pt[4]) not in self.ignore_links:
                        names = {v: k for k, v in o.links.items()}
                        return f"{o.id} ({names.get(pt[4], pt[4])}) at the {_link_name(r, pt[3])}", int(pt[3])
            for pt in p.getClosestPoints(r.body, w.table_body, -0.002, physicsClientId=w.client):
                return f"table at the {_link_name(r, pt[3])}", int(pt[3])
            return None

    def line(
        self, start: Pose, goal: Pose, seed: np.ndarray, check: bool = True, until_contact: bool = False
    ) -> list[np.ndarray]:
        """Configurations along the straight segment start -> goal (orientation slerped), collision-checked.

        ``until_contact``: stop before the first configuration that would touch something instead of
        failing (a descent that ends where the hand meets a wall top or a neighbour).
        """
        import pybullet as p

        dist = float(np.linalg.norm(goal[0] - start[0]))
        dq = p.getDifferenceQuaternion(start[1], goal[1])
        ang = 2 * math.acos(min(1.0, abs(dq[3])))
        n = max(1, math.ceil(max(dist / RESOLUTION, ang / 0.05)))
        out, q = [], seed
        for i in range(1, n + 1):
            t = i / n
            pos = start[0] + (goal[0] - start[0]) * t
            quat = p.getQuaternionSlerp(start[1], goal[1], t)
            q = self._continuous(q, pos, quat, self.solve(pos, quat, seed=q), goal[0])
            if check or until_contact:
                # stopping at contact keeps 3 mm: the hand must not end resting on a wall it may drag
                hit = self.collision(q, margin=0.003 if until_contact else 0.0)
                if hit is not None and until_contact:
                    break
                if hit is not None:
                    raise SkillError(
                        Failure.BLOCKED, f"path to {np.round(goal[0], 3).tolist()} collides with {hit}"
                    )
            out.append(q)
        return out

    def _continuous(
        self, prev: np.ndarray, pos: np.ndarray, quat: Sequence[float], q: np.ndarray, goal: np.ndarray
    ) -> np.ndarray:
        """``q``, or when it jumps from ``prev`` (an IK branch flip) a solution refined locally from
        ``prev``; IK_FLIP if there is none. Position control would swing the arm wildly through a flip."""
        jump = np.abs(q[2:] - prev[2:])
        if float(np.max(jump)) <= MAX_JOINT_JUMP:
            return q
        # damped least squares from the previous configuration stays on its branch when one exists
        again = self.robot.refine(prev, np.asarray(pos), quat, iters=80)
        dp, da = self.robot.fk_error(again, np.asarray(pos), quat)
        if dp < POS_TOL and da < ANG_TOL and float(np.max(np.abs(again[2:] - prev[2:]))) <= MAX_JOINT_JUMP:
            return again
        j = int(np.argmax(jump))
        raise SkillError(
            Failure.IK_FLIP,
            f"the straight path to {np.round(goal, 3).tolist()} needs an IK branch flip "
            f"(arm joint {j + 1} jumps {float(jump[j]):.2f} rad between waypoints)",
        )

    def move_continuous(self, goal: Pose, poses: list[Pose], check: bool = True) -> None:
        """A straight move to ``goal``; if it needs an IK branch flip, a collision-checked joint-space
        move to the configuration at ``goal`` from which the straight moves through ``poses`` (which
        start at ``goal``) stay continuous instead.

        Also where the straight move arrives with an arm from which those moves would need a flip (the
        wrist near its stop: a descent into a drawer solved from the transit configuration), the arm
        re-branches there in joint space (checked) before they start; if that move is blocked the arm
        stays as it arrived."""
        try:
            self.move_line(goal, check=check)
        except SkillError as exc:
            if exc.failure is not Failure.IK_FLIP:
                raise
            start = self.continuous_start(poses, self.robot.q()[:2])
            if start is None:
                raise
            self.move_joint(start, check=check)
            return
        if len(poses) < 2 or self.straight_path(poses, self.robot.q()) is not None:
            return
        start = self.continuous_start(poses, self.robot.q()[:2])
        if start is None:
            return
        try:
            self.move_joint(start, check=True)
        except SkillError as exc:
            if exc.failure is not Failure.BLOCKED:
                raise

    def move_rebranch(self, goal: Pose, check: bool = True) -> None:
        """A straight move to ``goal``; if it needs an IK branch flip (the arm sits against a joint limit
        that the straight path would have to cross: a wrist left at its stop by a tilted grasp), a
        collision-checked joint-space move to an IK solution at ``goal`` away from the limits instead,
        the one nearest the current configuration whose joint path touches nothing.

        ``check`` applies to the straight move only (a lift that starts in contact with what it grasped);
        a joint-space move sweeps the hand, so every one of its waypoints is always checked.
        """
        try:
            self.move_line(goal, check=check)
            return
        except SkillError as exc:
            if exc.failure is not Failure.IK_FLIP:
                raise
            flip = exc
        now = self.robot.q()
        ends = []
        for seed in (ARM_HOME, ARM_FRONT):
            q = self.robot.ik(np.asarray(goal[0]), goal[1], now[:2], seed=np.array((*now[:2], *seed)))
            dp, da = self.robot.fk_error(q, np.asarray(goal[0]), goal[1])
            if dp < POS_TOL and da < ANG_TOL:
                ends.append(q)
        ends.sort(key=lambda q: float(np.max(np.abs(q[2:] - now[2:]))))
        blocked: SkillError | None = None
        for q in ends:
            try:
                self.move_joint(q, check=True)
                return
            except SkillError as exc:
                if exc.failure is not Failure.BLOCKED:
                    raise
                blocked = blocked or exc
        raise blocked or flip

    # ------------------------------------------------------------ execution

    def step(self, n: int = 1) -> None:
        """Advance the world ``n`` steps, enforcing the budget."""
        if self.used + n > self.budget:
            raise SkillError(Failure.TIMEOUT, f"step budget of {self.budget} simulation steps exhausted")
        self.world.step(n)
        self.used += n

    def follow(self, qs: Iterable[np.ndarray], settle: int = 120) -> None:
        """Track configurations with position control, then wait (bounded) until the arm converges."""
        q = None
        for q in qs:
            if self.gentle:  # not a jump per waypoint: the jerks made a cube creep 9 cm to the far end
                # of a box held by its end wall (gsrgen_sod_complex_11's set-aside); same speed
                prev = self.robot.q() if self.robot.held is None else self.robot.held
                for j in range(1, STEPS_PER_WAYPOINT + 1):
                    self.robot.hold(prev + (q - prev) * j / STEPS_PER_WAYPOINT)
                    self.step(1)
                continue
            self.robot.hold(q)
            self.step(STEPS_PER_WAYPOINT)
        if q is None:
            return
        for _ in range(settle // 4):
            if float(np.max(np.abs(self.robot.q() - q))) < 0.01:
                return
            self.step(4)

    def pose(self) -> Pose:
        """The grasp point's current pose."""
        pos, quat = self.robot.ee_pose()
        return pos, tuple(float(v) for v in quat)  # type: ignore[return-value]

    def move_line(self, goal: Pose, check: bool = True) -> None:
        """Move the grasp point in a straight line to ``goal``."""
        self.follow(self.line(self.pose(), goal, self.robot.q(), check=check))

    def move_until_contact(self, goal: Pose) -> float:
        """Move straight towards ``goal`` as far as nothing is touched (1 cm steps); the distance left."""
        self.follow(self.line(self.pose(), goal, self.robot.q(), until_contact=True))
        return float(np.linalg.norm(goal[0] - self.pose()[0]))

    def move_base(self, x: float, y: float) -> None:
        """Slide the base on its rails (arm held still) to ``(x, y)``, clamped to the rails' range."""
        r = self.robot
        goal = np.clip([x, y], r.lower[:2], r.upper[:2])
        q = r.q()
        start = q[:2].copy()
        for a, b in itertools.pairwise([start, *self._base_route(start, goal), goal]):
            n = max(1, int(np.max(np.abs(b - a)) / 0.01))
            qs = []
            for i in range(1, n + 1):
                qq = q.copy()
                qq[:2] = a + (b - a) * i / n
                qs.append(qq)
            self.follow(qs)

    def _base_route(self, start: np.ndarray, goal: np.ndarray) -> list[np.ndarray]:
        """Waypoints for a base slide that would run into something (a stove by the table's edge): back
        off along x until the slide along y is clear, slide, come forward again; none when the straight
        slide is clear (or no backed-off slide is)."""
        r = self.robot
        q = r.q()

        def clear(a: np.ndarray, b: np.ndarray, arm: bool = False) -> bool:
            n = max(1, int(np.max(np.abs(b - a)) / 0.02))
            for i in range(1, n + 1):
                base = a + (b - a) * i / n
                if not self._base_clear(base, margin=0.005):
                    return False
                if arm and self.first_hit(np.array((*base, *q[2:]))) is not None:
                    return False
            return True

        if not clear(start, goal):
            straight = False
        elif self.first_hit(np.array((*start, *q[2:]))) is not None or clear(start, goal, arm=True):
            return []  # (an arm that touches something where it starts: the arm check cannot help)
        else:
            # the base slides clear but the arm, held as it is, would sweep through something: a pick's
            # straight slide along the cabinet's front carried the arm into the open top drawer and
            # pushed it 8 cm shut (gsrgen_sod_general_09), so the packing found no floor spot left
            straight = True
        # a route whose every leg also keeps the arm, held as it is, off everything (the leg forward
        # beside a cabinet's open drawer carried the shoulder into it and pushed the drawer shut),
        # coming forward up to 10 cm to the side of the goal and sliding in at the end; the first route
        # whose base alone is clear when there is none
        fallback: list[np.ndarray] = []
        for back in np.arange(min(start[0], goal[0]) - 0.05, r.lower[0] - 1e-9, -0.05):
            a, b = np.array([back, start[1]]), np.array([back, goal[1]])
            if not clear(a, b):
                continue
            fallback = fallback or [a, b]
            if back < min(start[0], goal[0]) - ROUTE_BACK_ARM:
                break
            for dy in (0.0, 0.05, -0.05, 0.1, -0.1):
                side = [np.array([back, goal[1] + dy]), np.array([goal[0], goal[1] + dy])] if dy else [b]
                legs = [start, a, *side, goal]
                if all(clear(u, v, arm=True) for u, v in itertools.pairwise(legs)):
                    return legs[1:-1]
        return [] if straight else fallback

    def park_for(
        self, target: np.ndarray, standoff: float = STANDOFF, poses: list[Pose] | None = None
    ) -> None:
        """Move the base so ``target`` lies about ``standoff`` in front of it (the arm's sweet spot).

        With ``poses``, the first base spot near there from which every pose has an IK solution wins
        (tried before anything moves); UNREACHABLE if none does. A spot where the arm at ``poses[0]``
        also touches nothing comes first (``plan_base(clear=True)``): beside a tall cabinet the first
        reachable spot may put the upper arm into the carcass, and the joint move to the stroke's start
        is then ``blocked`` where it begins; the first reachable spot when no spot is clear.
        """
        if not poses:
            self.move_base(float(target[0]) - standoff, float(target[1]))
            return
        try:
            base, _start = self.plan_base(target, poses, standoff, clear=True)
        except SkillError as exc:
            if exc.failure is Failure.TIMEOUT:
                raise
            base, _start = self.plan_base(target, poses, standoff)
        self.move_base(float(base[0]), float(base[1]))

    def plan_base(
        self,
        target: np.ndarray,
        poses: list[Pose],
        standoff: float = STANDOFF,
        clear: bool = False,
        path: bool = False,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(base, start)``: the first base spot near ``standoff`` in front of ``target`` from which every
        pose has an IK solution and the straight moves through them stay continuous, and the arm
        configuration at ``poses[0]`` there; nothing moves. UNREACHABLE if there is none.

        With ``clear`` the arm at ``poses[0]`` must also touch nothing: a base spot whose arm links hit
        something (an elbow over a box) gives way to the next; a hand or wrist that hits something does
        so from every spot (its pose is fixed), so that is BLOCKED at once. With ``path`` too, every
        configuration of the straight moves from ``start`` through the poses must touch nothing, and
        they are kept in :attr:`planned_path` (``poses[0]`` first) for :meth:`descend_planned`: the
        7-joint arm reaches a pose with many elbow and forearm positions, and a descent solved from
        wherever the arm arrived above the target may swing its forearm into a fixture the checked
        configuration cleared (an object beside a tall cabinet).
        """
        r = self.robot
        arm_hit = None
        self.planned_path = None
        for dx in (0.0, -0.05, 0.05, -0.1, 0.1, -0.15, -0.2):
            for dy in (0.0, -0.08, 0.08, -0.16, 0.16, -0.25, 0.25):
                base = np.clip([target[0] - standoff + dx, target[1] + dy], r.lower[:2], r.upper[:2])
                if self._base_clear(base) and all(self._reachable(pose, base) for pose in poses):
                    found = self.continuous_path(poses, base)
                    if found is None:
                        continue
                    start, qs = found
                    hit = self.first_hit(start) if clear else None
                    if hit is None and clear and path:
                        hit = next((h for q in qs for h in [self.first_hit(q)] if h is not None), None)
                        if hit is not None:
                            arm_hit = arm_hit or hit[0]
                            continue
                        self.planned_path = qs
                    if hit is None:
                        return base, start
                    if hit[1] >= r.arm[-1]:
                        raise SkillError(Failure.BLOCKED, f"grasp pose collides with {hit[0]}")
                    arm_hit = arm_hit or hit[0]
        if arm_hit is not None:
            raise SkillError(Failure.BLOCKED, f"from every base position the arm collides: {arm_hit}")
        raise SkillError(
            Failure.UNREACHABLE, f"no base position reaches the poses around {np.round(target, 3).tolist()}"
        )

    def _base_clear(self, base: np.ndarray, margin: float = 0.01) -> bool:
        """Whether the robot's base and shoulder at ``base`` stay clear of every object (fixtures by the edge)."""
        import pybullet as p

        r, w = self.robot, self.world
        with r.probe() as q:
            q[:2] = base
            r.reset(q)
            for o in w.objects.values():
                for link in (*r.base, r.arm[0]):
                    if p.getClosestPoints(r.body, o.body, margin, linkIndexA=link, physicsClientId=w.client):
                        return False
            return True

    def straight_path(self, poses: list[Pose], start: np.ndarray) -> list[np.ndarray] | None:
        """The configurations of the straight moves through ``poses`` (1 cm apart, ``start`` at
        ``poses[0]`` first, the base where ``start`` has it), or None where one needs an IK branch flip;
        nothing is checked for collision and the robot is left as it was."""
        with self.robot.probe():
            try:
                q, out = start, [start]
                for a, b in itertools.pairwise(poses):
                    self.robot.reset(q)
                    for nxt in self.line(a, b, q, check=False):
                        if float(np.max(np.abs(nxt[2:] - q[2:]))) > MAX_JOINT_JUMP:
                            return None
                        q = nxt
                        out.append(q)
                return out
            except SkillError:
                return None

    def descend_planned(self, poses: list[Pose]) -> None:
        """From above a target, move down through ``poses`` (the reverse of what :meth:`plan_base` was
        given with ``path``) along the configurations it checked: a joint-space move to the planned
        configuration above (checked) where the arm arrived there with another elbow, then the checked
        configurations down. Straight checked lines as before when there is no planned path for these
        poses or the arm cannot take its top configuration."""
        qs = self.planned_path
        if qs is not None:
            top = qs[-1].copy()
            top[:2] = self.robot.q()[:2]
            dp, da = self.robot.fk_error(top, np.asarray(poses[0][0]), poses[0][1])
            if dp < POS_TOL and da < ANG_TOL:
                try:
                    if float(np.max(np.abs(self.robot.q()[2:] - top[2:]))) > 0.01:
                        self.move_joint(top, check=True)
                except SkillError as exc:
                    if exc.failure is not Failure.BLOCKED:
                        raise
                else:
                    base = self.robot.q()[:2]
                    self.follow([np.array((*base, *q[2:])) for q in reversed(qs[:-1])])
                    return
        for pose in poses[1:]:
            self.move_line(pose)

    def continuous_start(self, poses: list[Pose], base: np.ndarray) -> np.ndarray | None:
        """An arm configuration at ``poses[0]`` from which straight moves through the poses (in order)
        need no IK branch flip (which position control cannot track), with the base at ``base``; or None."""
        found = self.continuous_path(poses, base)
        return None if found is None else found[0]

    def continuous_path(
        self, poses: list[Pose], base: np.ndarray
    ) -> tuple[np.ndarray, list[np.ndarray]] | None:
        """:meth:`continuous_start` with the configurations of its straight moves (:meth:`straight_path`);
        the robot is left as it was (each probe restores it)."""
        for seed in (ARM_HOME, ARM_FRONT):
            start = self.robot.ik(np.asarray(poses[0][0]), poses[0][1], base, seed=np.array((*base, *seed)))
            dp, da = self.robot.fk_error(start, np.asarray(poses[0][0]), poses[0][1])
            if dp >= POS_TOL or da >= ANG_TOL:
                continue
            qs = self.straight_path(poses, start)
            if qs is not None:
                return start, qs
        return None

    def move_joint(self, goal: np.ndarray, check: bool = True) -> None:
        """Move the arm in joint space to ``goal`` (base fixed), every waypoint collision-checked."""
        q0 = self.robot.q()
        goal = np.asarray(goal, dtype=float).copy()
        goal[:2] = q0[:2]
        n = max(1, math.ceil(float(np.max(np.abs(goal - q0))) / JOINT_STEP))
        qs = [q0 + (goal - q0) * i / n for i in range(1, n + 1)]
        if check:
            for q in qs:
                hit = self.collision(q)
                if hit is not None:
                    raise SkillError(Failure.BLOCKED, f"joint move collides with {hit}")
        self.follow(qs)

    def _reachable(self, pose: Pose, base: np.ndarray) -> bool:
        for seed in (ARM_HOME, ARM_FRONT):
            q = self.robot.ik(np.asarray(pose[0]), pose[1], base, seed=np.array((*base, *seed)))
            dp, da = self.robot.fk_error(q, np.asarray(pose[0]), pose[1])
            if dp < POS_TOL and da < ANG_TOL:
                return True
        return False

    def gripper(self, width: float, force: float = 40.0, steps: int = 60) -> float:
        """Drive the fingers to ``width`` (bounded wait) and return the width reached."""
        self.robot.command_gripper(width, force)
        last = self.robot.finger_width()
        for _ in range(steps // 6):
            self.step(6)
            now = self.robot.finger_width()
            if abs(now - last) < 2e-4 and abs(now - width) < 0.004:
                break
            last = now
        return self.robot.finger_width()

    def grasp_close(self) -> bool:
        """Close the fingers with the grasp force; True when they stopped on something, False on nothing."""
        width = self.gripper(0.0, force=GRIPPER.grasp_force, steps=GRIPPER.grasp_steps)
        return width >= GRIPPER.empty_width

    def release(self, width: float = GRIPPER.open_width) -> float:
        """Open the fingers to ``width`` (default fully open) over the release steps; the width reached."""
        return self.gripper(width, steps=GRIPPER.release_steps)
