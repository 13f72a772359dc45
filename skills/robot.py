"""The Franka Panda on a two-axis base (x and y rails): loading, IK, joint motion and the gripper.

The base slides on rails beside the table (x towards the table, y along its edge), like a mobile
manipulator parked at the table, so one arm reaches tables as wide as GSR-Bench's 1.2 m desk. Skills
move the base like any other joint (physically, position control), never by teleporting. PyBullet's
Panda (``pybullet_data/franka_panda``) is wrapped in a generated URDF that adds the two rails; the
IK keeps the rails where the skill put them (huge damping) and solves the seven arm joints.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from gsr.skills.assets import cache_dir

ARM_HOME = (0.0, -0.4, 0.0, -2.2, 0.0, 1.8, math.pi / 4)
#: An IK seed for tilted (front) approaches.
ARM_FRONT = (0.0, 0.2, 0.0, -2.0, 0.0, 2.2, math.pi / 4)
FINGER_OPEN = 0.04
DOWN_QUAT = (1.0, 0.0, 0.0, 0.0)  # rotation by pi about x: the gripper points down


@dataclass(frozen=True)
class GripperParams:
    """The Panda hand's numbers that every skill shares (widths are between the fingers, in metres)."""

    #: fully open: each finger joint at :data:`FINGER_OPEN`
    open_width: float = 2 * FINGER_OPEN
    #: closing force (N) on an object, a handle or a knob
    grasp_force: float = 60.0
    #: simulation steps a grasping close may take (bounded wait)
    grasp_steps: int = 90
    #: fingers closer than this after a grasping close met nothing
    empty_width: float = 0.002
    #: simulation steps of an opening release
    release_steps: int = 48


#: The gripper constants the skills use.
GRIPPER = GripperParams()


def _panda_on_rails(x_range: tuple[float, float], y_range: tuple[float, float]) -> Path:
    import pybullet_data

    src = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    text = src.read_text(encoding="utf-8")
    # absolute mesh paths so the generated file can live anywhere
    text = re.sub(
        r'filename="(?:package://)?(?!/)([^"]+)"', lambda m: f'filename="{src.parent / m.group(1)}"', text
    )
    massless = (
        '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'
    )
    rails = (
        f'<link name="rail">{massless}</link><link name="carriage">{massless}</link>\n'
        '<joint name="rail_x_joint" type="prismatic"><parent link="rail"/><child link="carriage"/>'
        f'<origin xyz="0 0 0"/><axis xyz="1 0 0"/><limit lower="{x_range[0]:.4f}" upper="{x_range[1]:.4f}" '
        'effort="2000" velocity="0.5"/></joint>\n'
        '<joint name="rail_y_joint" type="prismatic"><parent link="carriage"/><child link="panda_link0"/>'
        f'<origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="{y_range[0]:.4f}" upper="{y_range[1]:.4f}" '
        'effort="2000" velocity="0.5"/></joint>\n'
    )
    text = text.replace('<link name="panda_link0">', rails + '<link name="panda_link0">', 1)
    tag = f"{x_range[0]:.3f}_{x_range[1]:.3f}_{y_range[0]:.3f}_{y_range[1]:.3f}".replace("-", "m")
    path = cache_dir() / f"panda_rails_{tag}.urdf"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    return path


@dataclass
class Robot:
    """Indices and control of the Panda on its x/y base rails in one PyBullet client.

    Configurations ``q`` are 9 numbers: base x, base y, then the seven arm joints.
    """

    client: int
    body: int
    base: tuple[int, int] = (0, 1)
    arm: tuple[int, ...] = (2, 3, 4, 5, 6, 7, 8)
    fingers: tuple[int, int] = (11, 12)
    ee: int = 13
    lower: list[float] = field(default_factory=list)
    upper: list[float] = field(default_factory=list)
    # the rail and arm motors' position targets as last commanded (:meth:`hold`)
    held: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def load(
        cls, client: int, height: float, x_range: tuple[float, float], y_range: tuple[float, float]
    ) -> Robot:
        """Load the Panda at base height ``height`` with rails spanning ``x_range`` x ``y_range``, arm at home."""
        import pybullet as p

        body = p.loadURDF(
            str(_panda_on_rails(x_range, y_range)),
            (0.0, 0.0, height),
            useFixedBase=True,
            flags=p.URDF_USE_SELF_COLLISION_EXCLUDE_ALL_PARENTS,
            physicsClientId=client,
        )
        robot = cls(client, body)
        for j in range(p.getNumJoints(body, physicsClientId=client)):
            info = p.getJointInfo(body, j, physicsClientId=client)
            if info[2] != p.JOINT_FIXED:
                robot.lower.append(info[8])
                robot.upper.append(info[9])
            for link in robot.fingers:  # fingers grip by friction: give them grippy pads
                p.changeDynamics(
                    body, link, lateralFriction=1.5, spinningFriction=0.01, physicsClientId=client
                )
        # the real Panda's fingers are driven by one motor through a rack: couple them (equal openings).
        # Uncoupled, the two position-controlled fingers and a squeezed object float together along the
        # closing axis, and a held cube drifts a centimetre or two in the hand while the arm moves
        gear = p.createConstraint(
            body,
            robot.fingers[0],
            body,
            robot.fingers[1],
            jointType=p.JOINT_GEAR,
            jointAxis=(1, 0, 0),
            parentFramePosition=(0, 0, 0),
            childFramePosition=(0, 0, 0),
            physicsClientId=client,
        )
        p.changeConstraint(gear, gearRatio=-1, erp=0.1, maxForce=50, physicsClientId=client)
        robot.reset((x_range[0], 0.0, *ARM_HOME), FINGER_OPEN)
        return robot

    # ------------------------------------------------------------ state

    @property
    def joints(self) -> tuple[int, ...]:
        """Base and arm joint indices (the IK's controlled joints, in order)."""
        return (*self.base, *self.arm)

    def q(self) -> np.ndarray:
        """Current base + arm joint positions."""
        import pybullet as p

        return np.array([s[0] for s in p.getJointStates(self.body, self.joints, physicsClientId=self.client)])

    def finger_width(self) -> float:
        """Distance between the fingers (m)."""
        import pybullet as p

        return sum(s[0] for s in p.getJointStates(self.body, self.fingers, physicsClientId=self.client))

    def ee_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """World position and quaternion of the grasp point between the fingertips."""
        import pybullet as p

        s = p.getLinkState(self.body, self.ee, computeForwardKinematics=True, physicsClientId=self.client)
        return np.array(s[4]), np.array(s[5])

    def snapshot(self) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Rail and arm positions, velocities and motor targets, for :meth:`restore` after a probe."""
        import pybullet as p

        states = p.getJointStates(self.body, self.joints, physicsClientId=self.client)
        held = None if self.held is None else self.held.copy()
        return np.array([s[0] for s in states]), np.array([s[1] for s in states]), held

    def restore(self, snap: tuple[np.ndarray, np.ndarray, np.ndarray | None]) -> None:
        """Put back what :meth:`snapshot` saved: a probe that set joints (IK, collision checks) leaves
        the moving arm as it was. Restoring by :meth:`reset` to the measured positions would zero the
        joints' velocities and re-target the motors where the arm sagged under its load, so every probe
        let a loaded arm drift a little further (measured: LIBERO KITCHEN_SCENE6's mug release)."""
        import pybullet as p

        q, dq, held = snap
        for j, v, w in zip(self.joints, q, dq, strict=True):
            p.resetJointState(self.body, j, float(v), float(w), physicsClientId=self.client)
        self.hold(q if held is None else held)

    @contextlib.contextmanager
    def probe(self) -> Iterator[np.ndarray]:
        """A look-ahead that sets joints freely (IK, forward kinematics, collision checks): on leaving the
        block the arm is as it was (:meth:`snapshot` / :meth:`restore`: positions, velocities, held motor
        targets), also when the block raises. Yields a copy of the rail and arm positions it started from."""
        saved = self.snapshot()
        try:
            yield saved[0].copy()
        finally:
            self.restore(saved)

    def reset(self, q: tuple[float, ...] | np.ndarray, fingers: float | None = None) -> None:
        """Set joint positions directly (world setup and collision checking only, never during a skill)."""
        import pybullet as p

        for j, v in zip(self.joints, q, strict=True):
            p.resetJointState(self.body, j, float(v), physicsClientId=self.client)
        if fingers is not None:
            for j in self.fingers:
                p.resetJointState(self.body, j, fingers / 1.0, physicsClientId=self.client)
        self.hold(q)

    def hold(self, q: tuple[float, ...] | np.ndarray) -> None:
        """Command the rail and arm to hold positions ``q``."""
        import pybullet as p

        self.held = np.array(q, dtype=float)
        forces = [2000.0, 2000.0] + [87.0] * 4 + [12.0] * 3
        p.setJointMotorControlArray(
            self.body,
            list(self.joints),
            p.POSITION_CONTROL,
            targetPositions=[float(v) for v in q],
            forces=forces,
            positionGains=[0.3] * 9,
            physicsClientId=self.client,
        )

    def command_gripper(self, width: float, force: float = 40.0) -> None:
        """Drive both fingers towards a total opening ``width`` with at most ``force`` N each."""
        import pybullet as p

        for j in self.fingers:
            p.setJointMotorControl2(
                self.body,
                j,
                p.POSITION_CONTROL,
                targetPosition=width / 2,
                force=force,
                maxVelocity=0.1,
                physicsClientId=self.client,
            )

    def ik(
        self,
        pos: np.ndarray,
        quat: tuple[float, ...] | np.ndarray,
        base: tuple[float, float] | np.ndarray,
        seed: np.ndarray | None = None,
    ) -> np.ndarray:
        """Base + arm positions putting the grasp point at ``pos`` with orientation ``quat``, base fixed at ``base``."""
        import pybullet as p

        with self.probe():
            q = np.array(seed if seed is not None else (*base, *ARM_HOME), dtype=float)
            q[:2] = base
            # a huge damping on the rails keeps the solver from using them: the skill positions the base
            damping = [1000.0, 1000.0] + [0.1] * 9
            for _ in range(
                10
            ):  # refine from the previous solution: PyBullet's IK is one damped step at a time
                self.reset(q)
                sol = p.calculateInverseKinematics(
                    self.body,
                    self.ee,
                    [float(v) for v in pos],
                    [float(v) for v in quat],
                    jointDamping=damping,
                    maxNumIterations=100,
                    residualThreshold=1e-6,
                    physicsClientId=self.client,
                )
                q = np.clip(np.array(sol[:9]), self.lower[:9], self.upper[:9])
                q[:2] = base
                self.reset(q)
                got = self.ee_pose()[0]
                if float(np.linalg.norm(got - np.asarray(pos))) < 1e-3:
                    break
        dp, da = self.fk_error(q, np.asarray(pos), quat)
        if (dp > 1e-3 or da > 1e-2) and dp < 0.05:  # PyBullet's solver stalls near some orientations
            q = self.refine(q, np.asarray(pos), quat, iters=60)
        return q

    def refine(
        self, q0: np.ndarray, pos: np.ndarray, quat: tuple[float, ...] | np.ndarray, iters: int = 150
    ) -> np.ndarray:
        """Damped-least-squares IK on the 7 arm joints (base fixed) from ``q0``; pulls towards mid-range."""
        import pybullet as p

        with self.probe():
            q = np.array(q0, dtype=float)
            lo, hi = np.array(self.lower[2:9]), np.array(self.upper[2:9])
            mid = (lo + hi) / 2
            target = np.asarray(pos, dtype=float)
            r_tgt = np.array(p.getMatrixFromQuaternion(list(quat))).reshape(3, 3)
            for _ in range(iters):
                self.reset(q)
                got_p, got_q = self.ee_pose()
                r_cur = np.array(p.getMatrixFromQuaternion(list(got_q))).reshape(3, 3)
                r_err = r_tgt @ r_cur.T  # world-frame rotation still to go
                cos = float(np.clip((np.trace(r_err) - 1) / 2, -1.0, 1.0))
                angle = math.acos(cos)
                vee = np.array(
                    [r_err[2, 1] - r_err[1, 2], r_err[0, 2] - r_err[2, 0], r_err[1, 0] - r_err[0, 1]]
                )
                w_err = vee / (2 * math.sin(angle)) * angle if angle > 1e-6 else vee / 2
                if angle > math.pi - 1e-3:  # the formula degenerates at half a turn: nudge about any axis
                    w_err = np.array([0.0, 0.0, 0.5])
                err = np.concatenate([target - got_p, w_err])
                if np.linalg.norm(err[:3]) < 5e-4 and angle < 5e-3:
                    break
                states = [
                    s[0]
                    for s in p.getJointStates(
                        self.body, [*self.joints, *self.fingers], physicsClientId=self.client
                    )
                ]
                lin, ang = p.calculateJacobian(
                    self.body,
                    self.ee,
                    (0, 0, 0),
                    states,
                    [0.0] * len(states),
                    [0.0] * len(states),
                    physicsClientId=self.client,
                )
                jac = np.vstack([np.array(lin), np.array(ang)])[:, 2:9]
                lam = 0.05
                step = jac.T @ np.linalg.solve(jac @ jac.T + lam * lam * np.eye(6), err)
                null = np.eye(7) - np.linalg.pinv(jac) @ jac
                step += null @ (0.05 * (mid - q[2:9]))
                scale = max(1.0, float(np.max(np.abs(step))) / 0.2)
                q[2:9] = np.clip(q[2:9] + step / scale, lo + 1e-3, hi - 1e-3)
        return q

    def fk_error(
        self, q: np.ndarray, pos: np.ndarray, quat: tuple[float, ...] | np.ndarray
    ) -> tuple[float, float]:
        """Position (m) and orientation (rad) error of configuration ``q`` against a target pose."""
        import pybullet as p

        with self.probe():
            self.reset(q)
            got_p, got_q = self.ee_pose()
        dq = p.getDifferenceQuaternion(list(got_q), list(quat))
        angle = 2 * math.acos(min(1.0, abs(dq[3])))
        return float(np.linalg.norm(got_p - np.asarray(pos))), angle


def top_down(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion of a gripper pointing down whose fingers close along world direction ``yaw``."""
    import pybullet as p

    # with euler (pi, 0, a) the fingers close along world (-sin a, cos a), so a = yaw - pi/2; the gripper
    # is symmetric, so fold a into [-pi/2, pi/2) to keep joint 7 near the middle of its range
    a = (yaw - math.pi / 2 + math.pi / 2) % math.pi - math.pi / 2
    return tuple(p.getQuaternionFromEuler((math.pi, 0.0, a)))  # type: ignore[return-value]


def angled(
    yaw: float, pitch: float = 0.7, fingers_vertical: bool = True
) -> tuple[float, float, float, float]:
    """A gripper tilted forward along world direction ``yaw``: ``pitch`` rad from pointing straight down.

    With ``fingers_vertical`` the fingers close in the vertical plane of the approach (round a horizontal
    bar such as a drawer pull); otherwise they close horizontally (round a vertical bar). A fully
    horizontal hand needs contorted Panda configurations at table height; 40 degrees reaches everywhere.
    """
    import pybullet as p

    base = p.getQuaternionFromEuler((math.pi, -pitch, 0.0))
    if fingers_vertical:  # euler (pi, -pitch, 0) closes along world y: turn the hand a quarter about its axis
        base = p.multiplyTransforms(
            (0, 0, 0), base, (0, 0, 0), p.getQuaternionFromEuler((0, 0, math.pi / 2))
        )[1]
    return tuple(p.multiplyTransforms((0, 0, 0), p.getQuaternionFromEuler((0, 0, yaw)), (0, 0, 0), base)[1])  # type: ignore[return-value]


def approach_axis(quat: tuple[float, ...]) -> np.ndarray:
    """The direction the gripper points (its z axis) for an orientation."""
    import pybullet as p

    return np.array(p.getMatrixFromQuaternion(list(quat))).reshape(3, 3)[:, 2]


def _quat_from_matrix(m: np.ndarray, p: object) -> tuple[float, float, float, float]:
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    return (x, y, z, w)
