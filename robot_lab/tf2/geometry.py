"""tf2_geometry_msgs: geometry_msgs types moved through a TransformStamped, as upstream's
tf2_geometry_msgs.py does (and registered, so `buffer.transform(point, 'world')` works).

The results carry the transform's header, as upstream's do. `do_transform_vector3` zeroes
the translation of the transform it is given, as upstream's does (it rotates only).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from geometry_msgs.msg import (
    Point,
    Point32,
    PointStamped,
    PolygonStamped,
    Pose,
    PoseStamped,
    PoseWithCovarianceStamped,
    Vector3Stamped,
)

from robot_lab.tf2 import linear_math as lm
from robot_lab.tf2.buffer import ConvertRegistration, TransformRegistration

__all__ = [
    'do_transform_point',
    'do_transform_polygon_stamped',
    'do_transform_pose',
    'do_transform_pose_stamped',
    'do_transform_pose_with_covariance_stamped',
    'do_transform_vector3',
    'from_msg_msg',
    'to_msg_msg',
    'transform_covariance',
]


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


def _pose_of(transform: Any) -> tuple[lm.Vec, lm.Quat]:
    t, r = transform.transform.translation, transform.transform.rotation
    q = (r.x, r.y, r.z, r.w)
    n = math.sqrt(sum(c * c for c in q))
    unit = (0.0, 0.0, 0.0, 1.0) if n < 1.5e-8 else (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
    return (t.x, t.y, t.z), unit


def _apply(transform: Any, p: lm.Vec) -> lm.Vec:
    vec, quat = _pose_of(transform)
    return lm.add(lm.rotate(quat, p), vec)


def do_transform_point(point: PointStamped, transform: Any) -> PointStamped:
    x, y, z = _apply(transform, (point.point.x, point.point.y, point.point.z))
    res = PointStamped()
    res.point.x, res.point.y, res.point.z = x, y, z
    res.header = transform.header
    return res


def do_transform_vector3(vector3: Vector3Stamped, transform: Any) -> Vector3Stamped:
    transform.transform.translation.x = 0.0
    transform.transform.translation.y = 0.0
    transform.transform.translation.z = 0.0
    x, y, z = _apply(transform, (vector3.vector.x, vector3.vector.y, vector3.vector.z))
    res = Vector3Stamped()
    res.vector.x, res.vector.y, res.vector.z = x, y, z
    res.header = transform.header
    return res


def do_transform_pose(pose: Pose, transform: Any) -> Pose:
    vec, quat = _pose_of(transform)
    o = pose.orientation
    own = (o.x, o.y, o.z, o.w)
    n = math.sqrt(sum(c * c for c in own))
    own = (0.0, 0.0, 0.0, 1.0) if n < 1.5e-8 else (own[0] / n, own[1] / n, own[2] / n,
                                                    own[3] / n)
    x, y, z = lm.add(lm.rotate(quat, (pose.position.x, pose.position.y, pose.position.z)), vec)
    q = lm.multiply(quat, own)
    if q[3] < 0:  # upstream's matrix-to-quaternion keeps w >= 0
        q = (-q[0], -q[1], -q[2], -q[3])
    res = Pose()
    res.position.x, res.position.y, res.position.z = x, y, z
    res.orientation.x, res.orientation.y, res.orientation.z, res.orientation.w = q
    return res


def do_transform_pose_stamped(pose: PoseStamped, transform: Any) -> PoseStamped:
    res = PoseStamped()
    res.pose = do_transform_pose(pose.pose, transform)
    res.header = transform.header
    return res


def transform_covariance(cov_in: Any, transform: Any) -> Any:
    """The 6x6 covariance rotated block by block (upstream returns it in a
    PoseWithCovarianceStamped's pose.covariance)."""
    r = transform.transform.rotation
    q0, q1, q2, q3 = r.w, r.x, r.y, r.z
    rot = np.array(
        [[2 * (q0 * q0 + q1 * q1) - 1, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
         [2 * (q1 * q2 + q0 * q3), 2 * (q0 * q0 + q2 * q2) - 1, 2 * (q2 * q3 - q0 * q1)],
         [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 2 * (q0 * q0 + q3 * q3) - 1]])
    cov = np.asarray(cov_in, dtype=float).reshape(6, 6)
    out = np.zeros((6, 6))
    for i in (0, 3):
        for j in (0, 3):
            out[i:i + 3, j:j + 3] = rot @ cov[i:i + 3, j:j + 3] @ rot.T
    res = PoseWithCovarianceStamped()
    res.pose.covariance = out.reshape(36)
    return res.pose.covariance


def do_transform_pose_with_covariance_stamped(pose: PoseWithCovarianceStamped,
                                              transform: Any) -> PoseWithCovarianceStamped:
    res = PoseWithCovarianceStamped()
    res.pose.pose = do_transform_pose(pose.pose.pose, transform)
    res.pose.covariance = transform_covariance(pose.pose.covariance, transform)
    res.header = transform.header
    return res


def do_transform_polygon_stamped(polygon: PolygonStamped, transform: Any) -> PolygonStamped:
    res = PolygonStamped()
    for p in polygon.polygon.points:
        moved = do_transform_point(PointStamped(point=Point(x=p.x, y=p.y, z=p.z)), transform)
        res.polygon.points.append(Point32(x=moved.point.x, y=moved.point.y, z=moved.point.z))
    res.header = transform.header
    return res


for _type in (Vector3Stamped, PoseStamped, PointStamped):
    ConvertRegistration().add_to_msg(_type, to_msg_msg)
    ConvertRegistration().add_from_msg(_type, from_msg_msg)
TransformRegistration().add(PointStamped, do_transform_point)
TransformRegistration().add(Vector3Stamped, do_transform_vector3)
TransformRegistration().add(PoseStamped, do_transform_pose_stamped)
TransformRegistration().add(PoseWithCovarianceStamped, do_transform_pose_with_covariance_stamped)
TransformRegistration().add(PolygonStamped, do_transform_polygon_stamped)
