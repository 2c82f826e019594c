"""tf2_ros.static_transform_broadcaster (robot_lab.tf2.broadcasters)."""

from robot_lab.tf2.broadcasters import StaticTransformBroadcaster

__all__ = ['StaticTransformBroadcaster']
