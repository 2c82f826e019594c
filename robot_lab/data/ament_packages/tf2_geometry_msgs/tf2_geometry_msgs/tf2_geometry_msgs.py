"""tf2_geometry_msgs.tf2_geometry_msgs, upstream's module path (robot_lab.tf2.geometry)."""

from robot_lab.tf2.geometry import *  # noqa: F403
