"""Forward kinematics of a URDF joint tree, as robot_state_publisher computes it with KDL.

A joint's transform (parent link → child link) is its origin, then its motion: a rotation
about the axis (revolute, continuous) or a shift along it (prismatic). Rotations are 3×3
matrices in plain floats; the quaternion is read from the matrix as KDL's
`Rotation::GetQuaternion` reads it, so the messages carry the same signs as upstream's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from robot_lab.urdf.model import Joint, Robot

__all__ = [
    'Pose',
    'joint_pose',
    'link_poses',
    'mimic_positions',
    'quaternion',
    'rpy_matrix',
]

Matrix = tuple[tuple[float, float, float], tuple[float, float, float],
               tuple[float, float, float]]
Vector = tuple[float, float, float]
IDENTITY: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class Pose:
    """A rigid transform: `rotation` (row-major 3×3) then `translation`."""

    rotation: Matrix = IDENTITY
    translation: Vector = (0.0, 0.0, 0.0)

    def __mul__(self, other: Pose) -> Pose:
        r, t = self.rotation, self.translation
        moved = _apply(r, other.translation)
        return Pose(_matmul(r, other.rotation),
                    (moved[0] + t[0], moved[1] + t[1], moved[2] + t[2]))

    def quaternion(self) -> tuple[float, float, float, float]:
        """(x, y, z, w), as geometry_msgs orders it."""
        return quaternion(self.rotation)

    def matrix(self) -> list[list[float]]:
        """The 4×4 homogeneous matrix."""
        r, t = self.rotation, self.translation
        return [[*r[0], t[0]], [*r[1], t[1]], [*r[2], t[2]], [0.0, 0.0, 0.0, 1.0]]


def _matmul(a: Matrix, b: Matrix) -> Matrix:
    rows = tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3))
                 for i in range(3))
    return rows  # type: ignore[return-value]


def _apply(r: Matrix, v: Vector) -> Vector:
    return (r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
            r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
            r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2])


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """URDF's fixed-axis roll, pitch, yaw: Rz(yaw)·Ry(pitch)·Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def _axis_angle(axis: Vector, angle: float) -> Matrix:
    """Rodrigues' rotation about a unit axis."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    return ((c + x * x * v, x * y * v - z * s, x * z * v + y * s),
            (y * x * v + z * s, c + y * y * v, y * z * v - x * s),
            (z * x * v - y * s, z * y * v + x * s, c + z * z * v))


def quaternion(r: Matrix) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix, by KDL's branches (w > 0 when the trace is)."""
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 1e-6:  # KDL's epsilon
        s = 0.5 / math.sqrt(trace + 1.0)
        return ((r[2][1] - r[1][2]) * s, (r[0][2] - r[2][0]) * s,
                (r[1][0] - r[0][1]) * s, 0.25 / s)
    if r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = 2.0 * math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2])
        return (0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s,
                (r[2][1] - r[1][2]) / s)
    if r[1][1] > r[2][2]:
        s = 2.0 * math.sqrt(1.0 + r[1][1] - r[0][0] - r[2][2])
        return ((r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s,
                (r[0][2] - r[2][0]) / s)
    s = 2.0 * math.sqrt(1.0 + r[2][2] - r[0][0] - r[1][1])
    return ((r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s,
            (r[1][0] - r[0][1]) / s)


def joint_pose(joint: Joint, position: float = 0.0) -> Pose:
    """The child link's pose in the parent link's frame at joint `position`.

    Floating and planar joints are their origin alone, as KDL (robot_state_publisher)
    treats them.
    """
    origin = Pose(rpy_matrix(*joint.rpy), joint.xyz)
    if joint.type in ('revolute', 'continuous'):
        return origin * Pose(_axis_angle(joint.axis, position))
    if joint.type == 'prismatic':
        a = joint.axis
        return origin * Pose(translation=(a[0] * position, a[1] * position, a[2] * position))
    return origin


def mimic_positions(robot: Robot, positions: Mapping[str, float]) -> dict[str, float]:
    """`positions` plus each mimic joint whose leader is given (a given value is kept),
    as robot_state_publisher fills them in: leader × multiplier + offset."""
    full = dict(positions)
    for joint in robot.joints.values():
        if joint.mimic is not None and joint.mimic.joint in positions:
            full.setdefault(joint.name, positions[joint.mimic.joint] * joint.mimic.multiplier
                            + joint.mimic.offset)
    return full


def link_poses(robot: Robot, positions: Mapping[str, float] | None = None) -> dict[str, Pose]:
    """Every link's pose in the root link's frame (joints not given are at 0; mimic
    joints follow their leader)."""
    given = mimic_positions(robot, positions or {})
    poses = {robot.root: Pose()}
    stack = [robot.root]
    while stack:
        link = stack.pop()
        for joint in robot.child_joints.get(link, []):
            poses[joint.child] = poses[link] * joint_pose(joint, given.get(joint.name, 0.0))
            stack.append(joint.child)
    return poses
