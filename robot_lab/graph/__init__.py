"""The running ROS graph as data: nodes, topics, parameters, services, and its picture.

`robot_lab.graph.api` holds the functions (re-exported by `robot_lab`); `view` draws the
graph. Importing this package does not import rclpy; the first query does.
"""

from __future__ import annotations

from robot_lab.graph.api import *  # noqa: F403 - the package's API is api's
from robot_lab.graph.api import __all__ as _api_all

__all__ = list(_api_all)
