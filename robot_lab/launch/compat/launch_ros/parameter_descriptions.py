"""launch_ros.parameter_descriptions: ParameterValue, ParameterFile, Parameter."""

from __future__ import annotations

import typing
from typing import NoReturn

from robot_lab.launch.action import subs
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.parameters import ParamFileRef, ParamValue
from robot_lab.launch.substitutions import SomeSubstitutions, Substitution

__all__ = ['Parameter', 'ParameterFile', 'ParameterValue']

_SCALARS = {str: 'str', bool: 'bool', int: 'int', float: 'float'}


def _type_name(value_type: object) -> str | None:
    if value_type is None:
        return None
    if value_type in _SCALARS:
        return _SCALARS[value_type]
    if typing.get_origin(value_type) is list:
        (item,) = typing.get_args(value_type)
        return f'list_of_{_SCALARS[item]}'
    raise ValueError(f'unsupported value_type {value_type!r}')


def _has_substitutions(value: Substitution | list[object]) -> bool:
    """A substitution, or a list of text and substitutions (one string when evaluated)."""
    return isinstance(value, Substitution) or (
        any(isinstance(v, Substitution) for v in value)
        and all(isinstance(v, str | Substitution) for v in value))


class ParameterValue(ParamValue):
    """A value evaluated with YAML rules (or coerced to `value_type`) at launch."""

    def __init__(self, value: object, *, value_type: object = None) -> None:
        # substitutions are evaluated at launch; a plain str stays a str, as in launch
        if isinstance(value, Substitution | list) and _has_substitutions(value):
            value = subs(value)
        super().__init__(value, _type_name(value_type))


class ParameterFile(ParamFileRef):
    """A parameter file, optionally with substitutions inside it (allow_substs=True)."""

    def __init__(self, param_file: SomeSubstitutions, *, allow_substs: bool = False) -> None:
        super().__init__(subs(param_file), bool(allow_substs))


class Parameter:
    """One name/value pair; Node(parameters=[Parameter(...)]) passes it in a params file."""

    def __init__(self, name: str, value: object, *, value_type: object = None) -> None:
        self.name = name
        self.value = ParameterValue(value, value_type=value_type)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.parameter_descriptions', name, __all__)
