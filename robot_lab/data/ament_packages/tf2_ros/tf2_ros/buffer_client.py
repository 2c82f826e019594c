"""tf2_ros.buffer_client (robot_lab.tf2.buffer_server)."""

from robot_lab.tf2.buffer_server import BufferClient

__all__ = ['BufferClient']
