"""`<set_env>`, `<unset_env>`, `<append_env>` and their Python actions."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.registry import register
from robot_lab.launch.substitution_grammar import parse_substitution
from robot_lab.launch.substitutions import SomeSubstitutions, coerce, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['EnvironmentStep']


@register('set_env', 'unset_env', 'append_env')
class EnvironmentStep(LaunchStep):
    """set_env / unset_env / append_env."""

    def __init__(self, kind: str, name: SomeSubstitutions, value: SomeSubstitutions = '',
                 prepend: bool | SomeSubstitutions = False,
                 separator: SomeSubstitutions = os.pathsep) -> None:
        self.kind, self.name, self.value = kind, subs(name), subs(value)
        self.prepend = prepend if isinstance(prepend, bool) else subs(prepend)
        self.separator = subs(separator)

    def execute(self, context: LaunchContext) -> None:
        name = perform(self.name, context)
        env = context.environment
        if self.kind == 'set':
            env[name] = perform(self.value, context)
        elif self.kind == 'unset':
            env.pop(name, None)
        else:
            value, separator = perform(self.value, context), perform(self.separator, context)
            prepend = self.prepend if isinstance(self.prepend, bool) else coerce(
                perform(self.prepend, context), 'bool')
            if name in env:
                env[name] = value + separator + env[name] if prepend else \
                    env[name] + separator + value
            else:
                env[name] = value

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        if e.type_name == 'set_env':
            return cls('set', required(e, 'name'), required(e, 'value'))
        if e.type_name == 'unset_env':
            return cls('unset', required(e, 'name'))
        prepend = e.attr('prepend', 'bool_or_str')
        separator = e.attr('separator')
        return cls('append', required(e, 'name'), required(e, 'value'),
                   prepend if isinstance(prepend, bool) else
                   (parse_substitution(prepend) if prepend is not None else False),
                   separator if separator is not None else os.pathsep)
