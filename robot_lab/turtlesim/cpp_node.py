"""What an rclcpp node shows that an rclpy node does not, for turtlesim's nodes (C++ upstream).

rclcpp declares the QoS overrides of its /parameter_events publisher as read-only
parameters, and refuses to set a read-only parameter with its own words. The parameters
tutorial prints both (`param list`, `param dump`, `param load`), so the kit's turtlesim
nodes carry them too.
"""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

__all__ = ['CppNode']

# rclcpp's defaults for /parameter_events (rmw_qos_profile_parameter_events)
_PARAMETER_EVENTS_QOS = {'depth': 1000, 'durability': 'volatile', 'history': 'keep_last',
                         'reliability': 'reliable'}


class CppNode(Node):
    """An rclpy Node whose parameters look and refuse as an rclcpp node's do."""

    def __init__(self, name: str, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        for policy, value in _PARAMETER_EVENTS_QOS.items():
            self.declare_parameter(f'qos_overrides./parameter_events.publisher.{policy}',
                                   value, ParameterDescriptor(read_only=True))

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> SetParametersResult:
        for parameter in parameter_list:
            if self.has_parameter(parameter.name) and \
                    self.describe_parameter(parameter.name).read_only:
                return SetParametersResult(
                    successful=False, reason=f"parameter '{parameter.name}' cannot be set "
                    'because it is read-only')
        return super().set_parameters_atomically(parameter_list)
