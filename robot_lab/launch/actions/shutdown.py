"""`<shutdown>`/Shutdown: ends the whole launch."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity, sub_attr
from robot_lab.launch.plan import (
    ShutdownAction,
)
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['ShutdownStep']


@register('shutdown')
class ShutdownStep(LaunchStep):
    launch_name = 'Shutdown'

    def __init__(self, reason: SomeSubstitutions = '') -> None:
        self.reason = subs(reason)

    def execute(self, context: LaunchContext) -> None:
        context.sink.append(ShutdownAction(perform(self.reason, context),
                                           source=context.where()))

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(sub_attr(e, 'reason') or '')
