"""Poses and collision shapes, as SDF and URDF write them, added to a MuJoCo model spec.

Both formats give a pose as x y z and fixed-axis roll, pitch, yaw, and the same primitive
shapes (a box's full sizes, a cylinder along its z axis); MuJoCo wants half sizes and
(w, x, y, z) quaternions. One home for that arithmetic keeps the world and robot builders
from disagreeing on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.tf2.linear_math import quaternion_from_euler

__all__ = ['Shape', 'add_shape', 'quat_from_rpy']

Vec3 = tuple[float, float, float]


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> list[float]:
    """(w, x, y, z), MuJoCo's order, of R = Rz(yaw) Ry(pitch) Rx(roll): URDF's and SDF's
    convention, which is tf2's setRPY."""
    x, y, z, w = quaternion_from_euler(roll, pitch, yaw)
    return [w, x, y, z]


@dataclass(frozen=True)
class Shape:
    """A collision shape: `kind` box | cylinder | sphere | plane | mesh, in its frame."""

    kind: str
    size: tuple[float, ...]  # box: x y z; cylinder: radius length; sphere: radius
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    mesh: str = ''  # the name of a mesh asset already added to the spec


def add_shape(body: mujoco.MjsBody, shape: Shape, name: str,
              friction: float | None = None) -> mujoco.MjsGeom:
    """The shape as a geom of `body`; `friction` 0 makes it frictionless (a caster)."""
    geom = body.add_geom()
    geom.name = name
    geom.pos = list(shape.xyz)
    geom.quat = quat_from_rpy(*shape.rpy)
    if shape.kind == 'box':
        geom.type = mujoco.mjtGeom.mjGEOM_BOX
        geom.size = [shape.size[0] / 2, shape.size[1] / 2, shape.size[2] / 2]
    elif shape.kind == 'cylinder':
        geom.type = mujoco.mjtGeom.mjGEOM_CYLINDER
        geom.size = [shape.size[0], shape.size[1] / 2, 0.0]
    elif shape.kind == 'sphere':
        geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
        geom.size = [shape.size[0], 0.0, 0.0]
    elif shape.kind == 'plane':
        geom.type = mujoco.mjtGeom.mjGEOM_PLANE
        geom.size = [0.0, 0.0, 1.0]  # infinite, as Gazebo's ground plane collides
    else:
        geom.type = mujoco.mjtGeom.mjGEOM_MESH
        geom.meshname = shape.mesh
    if friction is not None:
        # MuJoCo takes the larger condim and friction of two touching geoms; Gazebo's ODE
        # the smaller mu: without priority a frictionless caster drags at the ground's mu
        geom.priority = 1  # this geom's own contact settings win against the ground's
        if friction <= 0.0:
            geom.condim = 1  # normal force only: Gazebo's mu1 = mu2 = 0
        else:
            geom.friction = [friction, 0.005, 0.0001]
    return geom
