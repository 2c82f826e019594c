"""A DiffDrive's wheels made to roll in MuJoCo as they do in Gazebo: odometry = ground truth.

Gazebo's DiffDrive on flat ground moves the robot as far as its odometry says. MuJoCo,
given a URDF's wheels as they are, did not (the body went 0.93 m for 0.995 m of odometry,
and turned 8 % less), for two reasons besides the caster (see `shapes.add_shape`):
- a cylinder touches a plane at the two edges of its rim: in a turn the inner and outer
  edge want different ground speeds, so the wheel scrubs. An ellipsoid of the wheel's
  radius and width touches at one point in the wheel's mid-plane, the contact of a
  rolling wheel (its outline differs from the cylinder's only at the rounded rim edges);
- a velocity servo with no torque limit spins a wheel up within a step, and the friction
  impulse throws the light robot off the ground. The wheel torque is limited to the
  URDF joint's `<limit effort>`, or else to half of what friction can pass to the ground
  (mu x the robot's weight per wheel x the radius), so the robot accelerates on its wheels.
"""

from __future__ import annotations

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed
import numpy as np

from robot_lab.sim.robot import SpawnedRobot
from robot_lab.urdf.model import Joint

__all__ = ['TRACTION_SHARE', 'round_wheel', 'wheel_torque']

TRACTION_SHARE = 0.5  # of the friction limit, for the default wheel torque
GRAVITY = 9.81


def _joint(robot: SpawnedRobot, name: str) -> Joint | None:
    for joints in robot.urdf.child_joints.values():
        for joint in joints:
            if joint.name == name:
                return joint
    return None


def round_wheel(spec: mujoco.MjSpec, robot: SpawnedRobot, joint_name: str) -> None:
    """The wheel link's cylinders about the joint's axis become ellipsoids of the same
    radius and width: one contact point in the wheel's plane instead of two at its rim."""
    joint = _joint(robot, joint_name)
    if joint is None:
        return
    axis = np.array(joint.axis, dtype=float)
    body = spec.body(robot.body(joint.child))
    for geom in body.geoms:
        if geom.type != mujoco.mjtGeom.mjGEOM_CYLINDER:
            continue
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, np.array(geom.quat, dtype=float))
        if abs(float(rotation.reshape(3, 3)[:, 2] @ axis)) < 0.99:  # not about the axle
            continue
        radius, half_width = float(geom.size[0]), float(geom.size[1])
        geom.type = mujoco.mjtGeom.mjGEOM_ELLIPSOID
        geom.size = [radius, radius, half_width]


def wheel_torque(spec: mujoco.MjSpec, robot: SpawnedRobot, joint_name: str, radius: float,
                 wheels: int) -> float:
    """The largest torque the wheel's servo gives: the URDF's effort limit when it has
    one, else half of what friction passes to the ground under the robot's weight."""
    joint = _joint(robot, joint_name)
    effort = joint.limit.effort if joint is not None and joint.limit is not None else None
    if effort is not None and effort > 0:
        return float(effort)
    mass = sum(float(spec.body(name).mass) for name in robot.bodies.values())
    mu = (robot.tags.friction.get(joint.child, 1.0) if joint is not None else 1.0) or 1.0
    return TRACTION_SHARE * mu * mass * GRAVITY / max(wheels, 1) * radius
