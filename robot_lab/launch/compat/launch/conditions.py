"""launch.conditions: IfCondition, UnlessCondition, LaunchConfigurationEquals/NotEquals."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.conditions import Condition, EqualsCondition
from robot_lab.launch.substitutions import SomeSubstitutions

__all__ = [
    'Condition',
    'IfCondition',
    'LaunchConfigurationEquals',
    'LaunchConfigurationNotEquals',
    'UnlessCondition',
]


class IfCondition(Condition):
    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        super().__init__(predicate_expression)


class UnlessCondition(Condition):
    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        super().__init__(predicate_expression, negate=True)


class LaunchConfigurationEquals(EqualsCondition):
    def __init__(self, launch_configuration_name: str,
                 expected_value: SomeSubstitutions | None) -> None:
        super().__init__(launch_configuration_name, expected_value)


class LaunchConfigurationNotEquals(EqualsCondition):
    def __init__(self, launch_configuration_name: str,
                 expected_value: SomeSubstitutions | None) -> None:
        super().__init__(launch_configuration_name, expected_value, negate=True)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.conditions', name, __all__)
