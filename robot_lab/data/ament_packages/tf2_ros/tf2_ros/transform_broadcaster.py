"""tf2_ros.transform_broadcaster (robot_lab.tf2.broadcasters)."""

from robot_lab.tf2.broadcasters import TransformBroadcaster

__all__ = ['TransformBroadcaster']
