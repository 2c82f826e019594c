"""Tags of valid ROS 2 launch files that robot_lab cannot run, each refused with its reason.

A composable-node container needs rclcpp_components (C++, not on PyPI); saying so, with
what to do instead, beats the "Unrecognized entity" a typo gets.
"""

from __future__ import annotations

from robot_lab.launch.action import LaunchStep
from robot_lab.launch.compat_path import COMPOSABLE_FIX
from robot_lab.launch.entity import Entity
from robot_lab.launch.registry import register

__all__ = ['ComposableNodesStep']


@register('node_container', 'load_composable_node', 'composable_node')
class ComposableNodesStep(LaunchStep):
    """Never built: parsing one is the error."""

    launch_name = 'ComposableNodeContainer'

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        raise e.fail(f'<{e.type_name}>: composable nodes are not supported by robot_lab',
                     fix=COMPOSABLE_FIX)
