"""`<timer>`/TimerAction: actions resolved now, started `period` s after launch."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity
from robot_lab.launch.plan import (
    TimerSpec,
)
from robot_lab.launch.registry import parse_entity, register
from robot_lab.launch.substitution_grammar import parse_substitution
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['TimerStep']


@register('timer')
class TimerStep(LaunchStep):
    """`<timer period>` / TimerAction: its actions resolved now, started later."""

    launch_name = 'TimerAction'
    runs_children_later = True

    def __init__(self, period: float | SomeSubstitutions, actions: Sequence[LaunchStep]) -> None:
        self.period = period if isinstance(period, float | int) else subs(period)
        self.actions = list(actions)

    def execute(self, context: LaunchContext) -> None:
        period = float(self.period if isinstance(self.period, float | int)
                       else perform(self.period, context))
        outer = context.sink
        context.sink = []
        try:
            context.run(self.actions)
            inner = context.sink
        finally:
            context.sink = outer
        outer.append(TimerSpec(period, inner, source=context.where()))

    def children(self) -> list[LaunchStep]:
        return self.actions

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        period = e.attr('period', 'float_or_str', optional=False)
        if isinstance(period, str):
            period = parse_substitution(period)
        e.attr('cancel_on_shutdown', 'bool_or_str')  # timers never outlive the plan here
        return cls(period, [parse_entity(c) for c in e.children()])
