"""launch.substitutions: the same substitution objects the XML/YAML `$(...)` forms build."""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import Any

from robot_lab.launch import boolean_substitutions as boolean
from robot_lab.launch import substitutions as core
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.substitutions import Substitution, SubstitutionFailure

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


def subs(value: Any) -> list[Substitution]:
    """launch's normalize_to_list_of_substitutions: text, a substitution, or a list of them."""
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, str):
        return [core.Text(value)]
    if isinstance(value, os.PathLike):
        return [core.Text(os.fspath(value))]
    if isinstance(value, Iterable):
        out: list[Substitution] = []
        for item in value:
            out.extend(subs(item))
        return out
    raise TypeError(f'expected str, Substitution or a list of them, got {value!r}')


def opt(value: Any) -> list[Substitution] | None:
    return None if value is None else subs(value)


class TextSubstitution(core.Text):
    def __init__(self, *, text: str) -> None:
        super().__init__(text)


class LaunchConfiguration(core.LaunchConfiguration):
    def __init__(self, variable_name: Any, *, default: Any = None) -> None:
        super().__init__(subs(variable_name), opt(default))


class EnvironmentVariable(core.EnvironmentVariable):
    def __init__(self, name: Any, *, default_value: Any = None) -> None:
        super().__init__(subs(name), opt(default_value))


class PythonExpression(core.PythonExpression):
    def __init__(self, expression: Any, python_modules: Any = None) -> None:
        modules: list[Substitution] | None = None
        if python_modules is not None:
            names = [python_modules] if isinstance(python_modules, str | Substitution) \
                else list(python_modules)
            modules = []
            for index, name in enumerate(names):
                if index:
                    modules.append(core.Text(','))
                modules.extend(subs(name))
        super().__init__(subs(expression), modules)


class PathJoinSubstitution(core.PathJoin):
    def __init__(self, substitutions: Iterable[Any]) -> None:
        super().__init__([subs(part) for part in substitutions])


class Command(core.Command):
    def __init__(self, command: Any, *, on_stderr: Any = 'fail') -> None:
        super().__init__(subs(command), subs(on_stderr))


class AnonName(core.AnonName):
    def __init__(self, name: Any) -> None:
        super().__init__(subs(name))


class ThisLaunchFileDir(core.ThisLaunchFileDir):
    pass


class ThisLaunchFile(core.ThisLaunchFile):
    pass


class FindExecutable(core.FindExecutable):
    def __init__(self, *, name: Any) -> None:
        super().__init__(subs(name))


class FileContent(core.FileContent):
    def __init__(self, path: Any) -> None:
        super().__init__(subs(path))


class NotSubstitution(boolean.Not):
    def __init__(self, value: Any) -> None:
        super().__init__(subs(value))


class AndSubstitution(boolean.And):
    def __init__(self, left: Any, right: Any) -> None:
        super().__init__(subs(left), subs(right))


class OrSubstitution(boolean.Or):
    def __init__(self, left: Any, right: Any) -> None:
        super().__init__(subs(left), subs(right))


class EqualsSubstitution(boolean.Equals):
    def __init__(self, left: Any, right: Any) -> None:
        super().__init__(subs(left), subs(right))


class IfElseSubstitution(boolean.IfElse):
    def __init__(self, condition: Any, if_value: Any = '', else_value: Any = '') -> None:
        super().__init__(subs(condition), subs(if_value), subs(else_value))


class NotEqualsSubstitution(boolean.NotEquals):
    def __init__(self, left: Any, right: Any) -> None:
        super().__init__(subs(left), subs(right))


class AnySubstitution(boolean.Any):
    def __init__(self, *args: Any) -> None:
        super().__init__(*(subs(arg) for arg in args))


class AllSubstitution(boolean.All):
    def __init__(self, *args: Any) -> None:
        super().__init__(*(subs(arg) for arg in args))


class LaunchLogDir(core.LaunchLogDir):
    pass


LocalSubstitution = core.LocalSubstitution


def __getattr__(name: str) -> Any:
    raise unsupported('launch.substitutions', name, __all__)
