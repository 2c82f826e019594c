"""tf2_ros.buffer: the Buffer (robot_lab.tf2.buffer)."""

from robot_lab.tf2.buffer import Buffer

__all__ = ['Buffer']
