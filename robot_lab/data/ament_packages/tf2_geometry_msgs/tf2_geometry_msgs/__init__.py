"""tf2_geometry_msgs, as robot_lab provides it (robot_lab.tf2.geometry).

Upstream's module has no __all__, so `from tf2_geometry_msgs import PointStamped` works
there too: the message types it imports are names here as well. The functions' list is
robot_lab.tf2.geometry's own, taken rather than restated.
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

from robot_lab.tf2 import geometry as _geometry
from robot_lab.tf2.geometry import *  # noqa: F403

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
]
__all__ += _geometry.__all__
