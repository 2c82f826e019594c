"""launch_ros.parameter_descriptions: ParameterValue, ParameterFile, Parameter."""

from __future__ import annotations

import typing
from typing import Any

from robot_lab.launch.compat.launch.substitutions import subs
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.parameters import ParamFileRef, ParamValue
from robot_lab.launch.substitutions import Substitution

__all__ = ['Parameter', 'ParameterFile', 'ParameterValue']

_SCALARS = {str: 'str', bool: 'bool', int: 'int', float: 'float'}


def _type_name(value_type: Any) -> str | None:
    if value_type is None:
        return None
    if value_type in _SCALARS:
        return _SCALARS[value_type]
    if typing.get_origin(value_type) is list:
        (item,) = typing.get_args(value_type)
        return f'list_of_{_SCALARS[item]}'
    raise ValueError(f'unsupported value_type {value_type!r}')


class ParameterValue(ParamValue):
    """A value evaluated with YAML rules (or coerced to `value_type`) at launch."""

    def __init__(self, value: Any, *, value_type: Any = None) -> None:
        mixed = isinstance(value, list) and any(isinstance(v, Substitution) for v in value) \
            and all(isinstance(v, str | Substitution) for v in value)
        if isinstance(value, Substitution) or mixed:
            value = subs(value)  # evaluated at launch; a plain str stays a str, as in launch
        super().__init__(value, _type_name(value_type))


class ParameterFile(ParamFileRef):
    """A parameter file, optionally with substitutions inside it (allow_substs=True)."""

    def __init__(self, param_file: Any, *, allow_substs: bool = False) -> None:
        super().__init__(subs(param_file), bool(allow_substs))


class Parameter:
    """One name/value pair; Node(parameters=[Parameter(...)]) passes it in a params file."""

    def __init__(self, name: Any, value: Any, *, value_type: Any = None) -> None:
        self.name = name
        self.value = ParameterValue(value, value_type=value_type)


def __getattr__(name: str) -> Any:
    raise unsupported('launch_ros.parameter_descriptions', name, __all__)
