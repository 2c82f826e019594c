"""tf2_geometry_msgs, as robot_lab provides it (robot_lab.tf2.geometry).

Upstream's module has no __all__, so `from tf2_geometry_msgs import PointStamped` works
there too: the message types it imports are names here as well.
"""

from geometry_msgs.msg import (
    Point,
    Point32,
    PointStamped,
    PolygonStamped,
    Pose,
    PoseStamped,
    PoseWithCovarianceStamped,
    TransformStamped,
    Vector3Stamped,
)

from robot_lab.tf2.geometry import (
    do_transform_point,
    do_transform_polygon_stamped,
    do_transform_pose,
    do_transform_pose_stamped,
    do_transform_pose_with_covariance_stamped,
    do_transform_vector3,
    from_msg_msg,
    to_msg_msg,
    transform_covariance,
)

__all__ = [
    'Point',
    'Point32',
    'PointStamped',
    'PolygonStamped',
    'Pose',
    'PoseStamped',
    'PoseWithCovarianceStamped',
    'TransformStamped',
    'Vector3Stamped',
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
