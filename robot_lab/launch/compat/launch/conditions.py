"""launch.conditions: IfCondition, UnlessCondition, LaunchConfigurationEquals/NotEquals."""

from __future__ import annotations

from typing import Any

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.conditions import Condition, EqualsCondition

__all__ = [
    'Condition',
    'IfCondition',
    'LaunchConfigurationEquals',
    'LaunchConfigurationNotEquals',
    'UnlessCondition',
]


class IfCondition(Condition):
    def __init__(self, predicate_expression: Any) -> None:
        super().__init__(predicate_expression)


class UnlessCondition(Condition):
    def __init__(self, predicate_expression: Any) -> None:
        super().__init__(predicate_expression, negate=True)


class LaunchConfigurationEquals(EqualsCondition):
    def __init__(self, launch_configuration_name: str, expected_value: Any) -> None:
        super().__init__(launch_configuration_name, expected_value)


class LaunchConfigurationNotEquals(EqualsCondition):
    def __init__(self, launch_configuration_name: str, expected_value: Any) -> None:
        super().__init__(launch_configuration_name, expected_value, negate=True)


def __getattr__(name: str) -> Any:
    raise unsupported('launch.conditions', name, __all__)
