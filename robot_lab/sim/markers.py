"""The world's shapes as visualization_msgs/Marker, for `scene_view().show_markers`.

Gazebo's GUI draws the world; the kit draws it in the notebook's 3D view, which knows TF
frames, not worlds. A Gazebo lab's RViz shows the robot in its odometry frame, which the
DiffDrive system starts at the robot's spawn pose: so the shapes are given in that frame
(`origin`: the spawn x, y and yaw), and line up with the robot and its scan.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed
import numpy as np

from robot_lab.sim.simulation import Simulation

__all__ = ['world_markers']

_SHAPES = {mujoco.mjtGeom.mjGEOM_BOX: 1, mujoco.mjtGeom.mjGEOM_SPHERE: 2,
           mujoco.mjtGeom.mjGEOM_CYLINDER: 3}  # Marker.CUBE, SPHERE, CYLINDER


def world_markers(sim: Simulation, frame_id: str = 'odom',
                  origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> list[Any]:
    """A Marker per box, sphere and cylinder of the world (not the robots', not the ground),
    posed in `frame_id`, whose pose in the world is x, y, yaw = `origin`."""
    from robot_lab.messages import message_class

    Marker = message_class('visualization_msgs/msg/Marker')  # noqa: N806 - a class

    robots = tuple(f'{name}::' for name in sim.robots)
    x0, y0, yaw0 = origin
    cos0, sin0 = math.cos(-yaw0), math.sin(-yaw0)
    markers = []
    model, data = sim.model, sim.data
    for geom in range(model.ngeom):
        kind = int(model.geom_type[geom])
        body = str(model.body(int(model.geom_bodyid[geom])).name)
        if kind not in _SHAPES or body.startswith(robots):
            continue
        marker = Marker()
        marker.header.frame_id = frame_id
        marker.ns = 'world'
        marker.id = geom
        marker.type = _SHAPES[kind]
        marker.action = Marker.ADD
        wx, wy, wz = (float(v) for v in data.geom_xpos[geom])
        dx, dy = wx - x0, wy - y0
        marker.pose.position.x = cos0 * dx - sin0 * dy
        marker.pose.position.y = sin0 * dx + cos0 * dy
        marker.pose.position.z = wz
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, data.geom_xmat[geom])
        turn = np.array([math.cos(-yaw0 / 2), 0.0, 0.0, math.sin(-yaw0 / 2)])
        posed = np.zeros(4)
        mujoco.mju_mulQuat(posed, turn, quat)
        orientation = marker.pose.orientation
        orientation.w, orientation.x, orientation.y, orientation.z = (float(v) for v in posed)
        size = [float(v) for v in model.geom_size[geom]]
        if marker.type == 1:
            scale = (2 * size[0], 2 * size[1], 2 * size[2])
        elif marker.type == 2:
            scale = (2 * size[0],) * 3
        else:
            scale = (2 * size[0], 2 * size[0], 2 * size[1])
        marker.scale.x, marker.scale.y, marker.scale.z = scale
        marker.color.r, marker.color.g, marker.color.b, marker.color.a = 0.7, 0.7, 0.75, 1.0
        markers.append(marker)
    return markers
