"""tf2_ros.transform_listener (robot_lab.tf2.listener)."""

from robot_lab.tf2.listener import TransformListener

__all__ = ['TransformListener']
