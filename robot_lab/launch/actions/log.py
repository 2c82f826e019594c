"""`<log>`/LogInfo: a line the launcher itself logs."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.plan import (
    LogAction,
)
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['LogStep']


@register('log')
class LogStep(LaunchStep):
    launch_name = 'LogInfo'

    def __init__(self, message: SomeSubstitutions, level: str = 'INFO') -> None:
        self.message, self.level = subs(message), level

    def execute(self, context: LaunchContext) -> None:
        context.sink.append(LogAction(perform(self.message, context), self.level,
                                      source=context.where()))

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(required(e, 'message'))
