"""`<arg>`/DeclareLaunchArgument and `<let>`/SetLaunchConfiguration."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, opt_subs, subs
from robot_lab.launch.entity import Entity, required, sub_attr
from robot_lab.launch.plan import (
    LaunchArgument,
)
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, Text, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['DeclareArgumentStep', 'SetConfigurationStep']


@register('arg')
class DeclareArgumentStep(LaunchStep):
    launch_name = 'DeclareLaunchArgument'

    def __init__(self, name: str, default: SomeSubstitutions | None = None, description: str = '',
                 choices: Sequence[str] | None = None) -> None:
        self.name = name
        self.default = opt_subs(default)
        self.description = description
        self.choices = None if choices is None else list(choices)

    def argument(self, context: LaunchContext | None = None) -> LaunchArgument:
        default = None
        if self.default is not None:
            default = perform(self.default, context) if context is not None else ''.join(
                s.text if isinstance(s, Text) else f'<{s.describe()}>' for s in self.default)
        return LaunchArgument(self.name, default, self.description, self.choices)

    def execute(self, context: LaunchContext) -> None:
        if self.name not in context.configurations:
            if self.default is None:
                raise context.error(
                    f'Required launch argument "{self.name}" was not provided.',
                    fix=f'add {self.name}:=<value> to the command line'
                    + (f' ({self.description})' if self.description else ''),
                )
            context.configurations[self.name] = perform(self.default, context)
        if self.choices is not None and context.configurations[self.name] not in self.choices:
            raise context.error(
                f'Argument "{self.name}" provided value "{context.configurations[self.name]}" '
                f'is not valid. Valid options are: {self.choices}')
        context.arguments.append(self.argument(context))

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        choices = e.entities('choice')
        values = None
        if choices is not None:
            values = [c.attr('value', optional=False) for c in choices]
            for c in choices:
                c.assert_parsed()
        return cls(e.attr('name', optional=False), sub_attr(e, 'default'),
                   e.attr('description') or '', values)


@register('let')
class SetConfigurationStep(LaunchStep):
    """`<let>` / SetLaunchConfiguration."""

    launch_name = 'SetLaunchConfiguration'

    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions) -> None:
        self.name, self.value = subs(name), subs(value)

    def execute(self, context: LaunchContext) -> None:
        context.configurations[perform(self.name, context)] = perform(self.value, context)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(required(e, 'name'), required(e, 'value'))


@register('reset')
class ResetConfigurationsStep(LaunchStep):
    """`<reset>` / ResetLaunchConfigurations: clear the configurations, `<keep>` some.

    launch_ros keeps the ROS namespace, global parameters and remaps among the launch
    configurations, so they are cleared too.
    """

    launch_name = 'ResetLaunchConfigurations'

    def __init__(self, keep: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None) -> None:
        self.keep = None if keep is None else [(subs(k), subs(v)) for k, v in keep.items()]

    def execute(self, context: LaunchContext) -> None:
        kept = {perform(k, context): perform(v, context) for k, v in self.keep or []}
        context.configurations.clear()
        context.configurations.update(kept)
        context.ros = {key: None for key in context.ros}

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        keeps = e.entities('keep')
        if keeps is None:
            return cls()
        keep = {tuple(required(k, 'name')): required(k, 'value') for k in keeps}
        for k in keeps:
            k.assert_parsed()
        return cls({tuple(k): v for k, v in keep.items()})


@register('unset')
class UnsetConfigurationStep(LaunchStep):
    """`<unset>` / UnsetLaunchConfiguration."""

    launch_name = 'UnsetLaunchConfiguration'

    def __init__(self, name: SomeSubstitutions) -> None:
        self.name = subs(name)

    def execute(self, context: LaunchContext) -> None:
        context.configurations.pop(perform(self.name, context), None)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(required(e, 'name'))


class ScopeStep(LaunchStep):
    """Push/PopLaunchConfigurations, Push/PopEnvironment, ResetEnvironment (Python only)."""

    def __init__(self, operation: str, what: str) -> None:
        self.operation, self.what = operation, what
        self.launch_name = {'push': 'Push', 'pop': 'Pop', 'reset': 'Reset'}[operation] + (
            'LaunchConfigurations' if what == 'configurations' else 'Environment')

    def execute(self, context: LaunchContext) -> None:
        if self.operation == 'reset':
            context.environment = dict(context.initial_environment)
        elif self.operation == 'push':
            context.push(self.what)
        else:
            context.pop(self.what)
