"""`<group>`/GroupAction: scoped launch configurations and environment."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.registry import parse_entity, register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['GroupStep']


@register('group')
class GroupStep(LaunchStep):
    """`<group>` / GroupAction: scoped by default (configurations and environment)."""

    launch_name = 'GroupAction'

    def __init__(self, actions: Sequence[LaunchStep], scoped: bool = True, forwarding: bool = True,
                 keep: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None) -> None:
        self.actions = list(actions)
        self.scoped, self.forwarding = scoped, forwarding
        self.keep = [(subs(k), subs(v)) for k, v in (keep or {}).items()]

    def execute(self, context: LaunchContext) -> None:
        if not self.scoped:
            for name, value in self.keep:
                context.configurations[perform(name, context)] = perform(value, context)
            context.run(self.actions)
            return
        context.push()
        try:
            kept = {perform(n, context): perform(v, context) for n, v in self.keep}
            if not self.forwarding:
                context.configurations = {}
                context.ros = {key: None for key in context.ros}
                context.environment = dict(context.initial_environment)
            context.configurations.update(kept)
            context.run(self.actions)
        finally:
            context.pop()

    def children(self) -> list[LaunchStep]:
        return self.actions

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        scoped = e.attr('scoped', 'bool')
        forwarding = e.attr('forwarding', 'bool')
        keeps = e.entities('keep') or []
        keep = {tuple(required(k, 'name')): required(k, 'value') for k in keeps}
        for k in keeps:
            k.assert_parsed()
        actions = [parse_entity(c) for c in e.children() if c.type_name != 'keep']
        return cls(actions, True if scoped is None else scoped,
                   True if forwarding is None else forwarding,
                   {tuple(k): v for k, v in keep.items()})
