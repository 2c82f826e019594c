"""Conditions on actions: `if=`/`unless=`, IfCondition, LaunchConfigurationEquals ..."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.launch.action import opt_subs, subs
from robot_lab.launch.substitutions import SomeSubstitutions, condition_value, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['Condition', 'EqualsCondition']


class Condition:
    """IfCondition / UnlessCondition: 'true'/'1' or 'false'/'0', else an error."""

    def __init__(self, expression: SomeSubstitutions, negate: bool = False) -> None:
        self.expression = subs(expression)
        self.negate = negate

    def evaluate(self, context: LaunchContext) -> bool:
        return condition_value(perform(self.expression, context)) != self.negate

    def describe(self) -> str:
        """For --print: the expression, never evaluated."""
        kind = 'UnlessCondition' if self.negate else 'IfCondition'
        return f"{kind}({' + '.join(s.describe() for s in self.expression)})"


class EqualsCondition(Condition):
    """LaunchConfigurationEquals / NotEquals."""

    def __init__(self, name: str, value: SomeSubstitutions | None, negate: bool = False) -> None:
        self.name, self.value, self.negate = name, opt_subs(value), negate

    def evaluate(self, context: LaunchContext) -> bool:
        value = None if self.value is None else perform(self.value, context)
        return (context.configurations.get(self.name) == value) != self.negate

    def describe(self) -> str:
        kind = 'LaunchConfigurationNotEquals' if self.negate else 'LaunchConfigurationEquals'
        value = 'None' if self.value is None else ' + '.join(s.describe() for s in self.value)
        return f'{kind}({self.name!r}, {value})'
