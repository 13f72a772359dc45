"""The Franka Panda on a linear rail: loading, inverse kinematics, joint motion and the gripper.

The rail (a prismatic joint along world y under the arm's base) lets one arm reach tables as wide as
GSR-Bench's 1.2 m desk; skills move it like any other joint, physically, never by teleporting.
PyBullet's Panda (``pybullet_data/franka_panda``) is wrapped in a generated URDF that adds the rail.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skills.assets import cache_dir

ARM_HOME = (0.0, -0.4, 0.0, -2.2, 0.0, 1.8, math.pi / 4)
#: An IK seed for horizontal (front) approaches: PyBullet's solver does not find them from ARM_HOME.
ARM_FRONT = (0.0, 0.2, 0.0, -2.0, 0.0, 2.2, math.pi / 4)
FINGER_OPEN = 0.04
RAIL_RANGE = 0.7
#: Where the fingertips' grasp point sits below the hand's flange (the URDF's grasptarget link).
DOWN_QUAT = (1.0, 0.0, 0.0, 0.0)  # rotation by pi about x: the gripper points down


def _panda_with_rail() -> Path:
    import pybullet_data

    src = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    text = src.read_text(encoding="utf-8")
    # absolute mesh paths so the generated file can live anywhere
    text = re.sub(
        r'filename="(?:package://)?(?!/)([^"]+)"', lambda m: f'filename="{src.parent / m.group(1)}"', text
    )
    rail = (
        '<link name="rail"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
        "</inertial></link>"
        '<joint name="rail_joint" type="prismatic"><parent link="rail"/><child link="panda_link0"/>'
        f'<origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="{-RAIL_RANGE}" upper="{RAIL_RANGE}" '
        'effort="500" velocity="0.5"/></joint>'
    )
    text = text.replace('<link name="panda_link0">', rail + '<link name="panda_link0">', 1)
    path = cache_dir() / "panda_rail.urdf"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    return path


@dataclass
class Robot:
    """Indices and control of the rail-mounted Panda in one PyBullet client."""

    client: int
    body: int
    rail: int = 0
    arm: tuple[int, ...] = (1, 2, 3, 4, 5, 6, 7)
    fingers: tuple[int, int] = (10, 11)
    ee: int = 12
    lower: list[float] = field(default_factory=list)
    upper: list[float] = field(default_factory=list)

    @classmethod
    def load(cls, client: int, base: tuple[float, float, float]) -> Robot:
        """Load the Panda with its rail at ``base`` (the rail's centre), arm at home, gripper open."""
        import pybullet as p

        body = p.loadURDF(
            str(_panda_with_rail()),
            base,
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
        robot.reset((0.0, *ARM_HOME), FINGER_OPEN)
        return robot

    # ------------------------------------------------------------ state

    @property
    def joints(self) -> tuple[int, ...]:
        """Rail and arm joint indices (the IK's controlled joints, in order)."""
        return (self.rail, *self.arm)

    def q(self) -> np.ndarray:
        """Current rail + arm joint positions."""
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

        forces = [800.0] + [87.0] * 4 + [12.0] * 3
        p.setJointMotorControlArray(
            self.body,
            list(self.joints),
            p.POSITION_CONTROL,
            targetPositions=[float(v) for v in q],
            forces=forces,
            positionGains=[0.3] * 8,
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
        rail_y: float,
        seed: np.ndarray | None = None,
    ) -> np.ndarray:
        """Rail + arm positions putting the grasp point at ``pos`` with orientation ``quat``, rail at ``rail_y``."""
        import pybullet as p

        saved = self.q()
        q = np.array(seed if seed is not None else (rail_y, *ARM_HOME), dtype=float)
        q[0] = rail_y
        # a huge damping on the rail keeps the solver from using it: the rail is positioned by the skill
        damping = [1000.0] + [0.1] * 9
        for _ in range(4):  # refine from the previous solution: PyBullet's IK is one damped step at a time
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
            q = np.clip(np.array(sol[:8]), self.lower[:8], self.upper[:8])
            q[0] = rail_y
        self.reset(saved)
        return q

    def fk_error(
        self, q: np.ndarray, pos: np.ndarray, quat: tuple[float, ...] | np.ndarray
    ) -> tuple[float, float]:
        """Position (m) and orientation (rad) error of configuration ``q`` against a target pose."""
        import pybullet as p

        saved = self.q()
        self.reset(q)
        got_p, got_q = self.ee_pose()
        self.reset(saved)
        dq = p.getDifferenceQuaternion(list(got_q), list(quat))
        angle = 2 * math.acos(min(1.0, abs(dq[3])))
        return float(np.linalg.norm(got_p - np.asarray(pos))), angle


def top_down(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion of a gripper pointing down whose fingers close along world direction ``yaw``."""
    import pybullet as p

    # with euler (pi, 0, a) the fingers close along world (cos a, sin a); the gripper is symmetric, so
    # fold the yaw into [-pi/2, pi/2) to keep joint 7 near the middle of its range
    a = (yaw + math.pi / 2) % math.pi - math.pi / 2
    return tuple(p.getQuaternionFromEuler((math.pi, 0.0, a)))  # type: ignore[return-value]


def pointing(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion of a horizontal gripper pointing along world direction ``yaw`` with fingers closing vertically."""
    import pybullet as p

    # hand frame: z (approach) = (cos, sin, 0); y (closing) = world z; x = y cross z
    z = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    y = np.array([0.0, 0.0, 1.0])
    x = np.cross(y, z)
    m = np.column_stack([x, y, z])
    return _quat_from_matrix(m, p)


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
