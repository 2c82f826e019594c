"""launch.substitutions: the same substitution objects the XML/YAML `$(...)` forms build."""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import NoReturn

from robot_lab.launch import boolean_substitutions as boolean
from robot_lab.launch import substitutions as core
from robot_lab.launch.action import opt_subs as opt
from robot_lab.launch.action import subs
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.substitutions import (
    SomeSubstitution,
    SomeSubstitutions,
    Substitution,
    SubstitutionFailure,
)

__all__ = [
    'AllSubstitution',
    'AndSubstitution',
    'AnonName',
    'AnySubstitution',
    'Command',
    'EnvironmentVariable',
    'EqualsSubstitution',
    'FileContent',
    'FindExecutable',
    'IfElseSubstitution',
    'LaunchConfiguration',
    'LaunchLogDir',
    'LocalSubstitution',
    'NotEqualsSubstitution',
    'NotSubstitution',
    'OrSubstitution',
    'PathJoinSubstitution',
    'PythonExpression',
    'Substitution',
    'SubstitutionFailure',
    'TextSubstitution',
    'ThisLaunchFile',
    'ThisLaunchFileDir',
]


class TextSubstitution(core.Text):
    def __init__(self, *, text: str) -> None:
        super().__init__(text)


class LaunchConfiguration(core.LaunchConfiguration):
    def __init__(self, variable_name: SomeSubstitutions, *,
                 default: SomeSubstitutions | None = None) -> None:
        super().__init__(subs(variable_name), opt(default))


class EnvironmentVariable(core.EnvironmentVariable):
    def __init__(self, name: SomeSubstitutions, *,
                 default_value: SomeSubstitutions | None = None) -> None:
        super().__init__(subs(name), opt(default_value))


class PythonExpression(core.PythonExpression):
    def __init__(self, expression: SomeSubstitutions,
                 python_modules: SomeSubstitutions | None = None) -> None:
        modules: list[Substitution] | None = None
        if python_modules is not None:
            names: list[SomeSubstitution]
            if isinstance(python_modules, str | os.PathLike | Substitution):
                names = [python_modules]
            else:
                names = list(python_modules)
            modules = []
            for index, name in enumerate(names):
                if index:
                    modules.append(core.Text(','))
                modules.extend(subs(name))
        super().__init__(subs(expression), modules)


class PathJoinSubstitution(core.PathJoin):
    def __init__(self, substitutions: Iterable[SomeSubstitutions]) -> None:
        super().__init__([subs(part) for part in substitutions])


class Command(core.Command):
    def __init__(self, command: SomeSubstitutions, *,
                 on_stderr: SomeSubstitutions = 'fail') -> None:
        super().__init__(subs(command), subs(on_stderr))


class AnonName(core.AnonName):
    def __init__(self, name: SomeSubstitutions) -> None:
        super().__init__(subs(name))


class ThisLaunchFileDir(core.ThisLaunchFileDir):
    pass


class ThisLaunchFile(core.ThisLaunchFile):
    pass


class FindExecutable(core.FindExecutable):
    def __init__(self, *, name: SomeSubstitutions) -> None:
        super().__init__(subs(name))


class FileContent(core.FileContent):
    def __init__(self, path: SomeSubstitutions) -> None:
        super().__init__(subs(path))


class NotSubstitution(boolean.Not):
    def __init__(self, value: SomeSubstitutions) -> None:
        super().__init__(subs(value))


class AndSubstitution(boolean.And):
    def __init__(self, left: SomeSubstitutions, right: SomeSubstitutions) -> None:
        super().__init__(subs(left), subs(right))


class OrSubstitution(boolean.Or):
    def __init__(self, left: SomeSubstitutions, right: SomeSubstitutions) -> None:
        super().__init__(subs(left), subs(right))


class EqualsSubstitution(boolean.Equals):
    def __init__(self, left: SomeSubstitutions, right: SomeSubstitutions) -> None:
        super().__init__(subs(left), subs(right))


class IfElseSubstitution(boolean.IfElse):
    def __init__(self, condition: SomeSubstitutions, if_value: SomeSubstitutions = '',
                 else_value: SomeSubstitutions = '') -> None:
        super().__init__(subs(condition), subs(if_value), subs(else_value))


class NotEqualsSubstitution(boolean.NotEquals):
    def __init__(self, left: SomeSubstitutions, right: SomeSubstitutions) -> None:
        super().__init__(subs(left), subs(right))


class AnySubstitution(boolean.AnyTrue):
    def __init__(self, *args: SomeSubstitutions) -> None:
        super().__init__(*(subs(arg) for arg in args))


class AllSubstitution(boolean.AllTrue):
    def __init__(self, *args: SomeSubstitutions) -> None:
        super().__init__(*(subs(arg) for arg in args))


class LaunchLogDir(core.LaunchLogDir):
    pass


LocalSubstitution = core.LocalSubstitution


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.substitutions', name, __all__)
