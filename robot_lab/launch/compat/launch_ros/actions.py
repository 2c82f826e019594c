"""launch_ros.actions: Node, PushROSNamespace, SetParameter, SetParametersFromFile, SetRemap."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from typing import Any, NoReturn

from robot_lab.launch.action import subs
from robot_lab.launch.actions.lifecycle_node import LifecycleNodeStep
from robot_lab.launch.actions.namespace import PushNamespaceStep
from robot_lab.launch.actions.node import NodeStep
from robot_lab.launch.actions.ros_globals import GlobalRosStep, SetUseSimTimeStep
from robot_lab.launch.compat.launch.actions import _place, process_options
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.conditions import Condition
from robot_lab.launch.parameters import NodeParameters, ParamFileRef, ParamValue
from robot_lab.launch.substitutions import SomeSubstitutions, Substitution

# Node(remappings=[('from', 'to'), ...])
Remappings = Iterable[tuple[SomeSubstitutions, SomeSubstitutions]]

__all__ = [
    'LifecycleNode',
    'Node',
    'PushROSNamespace',
    'PushRosNamespace',
    'SetParameter',
    'SetParametersFromFile',
    'SetRemap',
    'SetUseSimTime',
]


def _value(value: object) -> object:
    """launch_ros's normalize_parameter_dict for one value."""
    if isinstance(value, Mapping):
        return {k: _value(v) for k, v in value.items()}
    if isinstance(value, ParamValue | str | bool | int | float | bytes):
        return value
    if isinstance(value, Substitution):
        return ParamValue(subs(value))
    if isinstance(value, list | tuple):
        if any(isinstance(v, Substitution) for v in value) and \
                all(isinstance(v, str | Substitution) for v in value):
            return ParamValue(subs(value))  # one string made of the parts
        if any(isinstance(v, list | tuple) for v in value):
            return ParamValue([subs(v) for v in value])  # a list of strings
        return list(value)
    raise TypeError(f'Unexpected type for parameter value {value!r}')


def _parameters(parameters: Iterable[object]) -> list[NodeParameters]:
    result: list[NodeParameters] = []
    for entry in parameters:
        if isinstance(entry, Mapping):
            result.append({k: _value(v) for k, v in entry.items()})
        elif hasattr(entry, 'name') and hasattr(entry, 'value') and \
                isinstance(entry.value, ParamValue):
            result.append({entry.name: entry.value})  # a Parameter (from either import path)
        elif isinstance(entry, ParamFileRef):
            result.append(entry)
        elif isinstance(entry, str | os.PathLike | Substitution | list | tuple):
            result.append(ParamFileRef(subs(entry)))
        else:
            raise TypeError(f'Expecting list of parameters, got {entry!r}')
    return result


def _node_fields(parameters: Iterable[object] | None, remappings: Remappings | None,
                 ros_arguments: Iterable[SomeSubstitutions] | None,
                 arguments: Iterable[SomeSubstitutions] | None,
                 kwargs: dict[str, Any]) -> dict[str, Any]:
    """What Node and LifecycleNode take alike, as their steps want it (lists, our options)."""
    return {
        'parameters': _parameters(parameters) if parameters is not None else None,
        'remappings': list(remappings) if remappings is not None else None,
        'ros_arguments': list(ros_arguments) if ros_arguments is not None else None,
        'arguments': list(arguments) if arguments is not None else None,
        'options': process_options(**kwargs),
    }


class Node(NodeStep):
    def __init__(self, *, executable: SomeSubstitutions, package: SomeSubstitutions | None = None,
                 name: SomeSubstitutions | None = None,
                 namespace: SomeSubstitutions | None = None,
                 exec_name: SomeSubstitutions | None = None,
                 parameters: Iterable[object] | None = None,
                 remappings: Remappings | None = None,
                 ros_arguments: Iterable[SomeSubstitutions] | None = None,
                 arguments: Iterable[SomeSubstitutions] | None = None,
                 condition: Condition | None = None, **kwargs: Any) -> None:
        kwargs.pop('name', None)
        super().__init__(
            executable, package=package, name=name, namespace=namespace, exec_name=exec_name,
            **_node_fields(parameters, remappings, ros_arguments, arguments, kwargs),
        )
        _place(self, condition)


class LifecycleNode(LifecycleNodeStep):
    def __init__(self, *, executable: SomeSubstitutions, name: SomeSubstitutions | None = None,
                 namespace: SomeSubstitutions | None = None,
                 autostart: bool = False, package: SomeSubstitutions | None = None,
                 exec_name: SomeSubstitutions | None = None,
                 parameters: Iterable[object] | None = None,
                 remappings: Remappings | None = None,
                 ros_arguments: Iterable[SomeSubstitutions] | None = None,
                 arguments: Iterable[SomeSubstitutions] | None = None,
                 condition: Condition | None = None, **kwargs: Any) -> None:
        super().__init__(
            executable, autostart=autostart, package=package, name=name, namespace=namespace,
            exec_name=exec_name,
            **_node_fields(parameters, remappings, ros_arguments, arguments, kwargs),
        )
        _place(self, condition)


class PushROSNamespace(PushNamespaceStep):
    def __init__(self, namespace: SomeSubstitutions, *, condition: Condition | None = None) -> None:
        super().__init__(namespace)
        _place(self, condition)


PushRosNamespace = PushROSNamespace


class SetParameter(GlobalRosStep):
    def __init__(self, name: SomeSubstitutions, value: object, *,
                 condition: Condition | None = None) -> None:
        super().__init__('parameter', name, _value(value))
        _place(self, condition)


class SetParametersFromFile(GlobalRosStep):
    def __init__(self, filename: SomeSubstitutions, *, condition: Condition | None = None) -> None:
        super().__init__('file', filename)
        _place(self, condition)


class SetRemap(GlobalRosStep):
    def __init__(self, src: SomeSubstitutions, dst: SomeSubstitutions, *,
                 condition: Condition | None = None) -> None:
        super().__init__('remap', src, dst)
        _place(self, condition)




class SetUseSimTime(SetUseSimTimeStep):
    def __init__(self, value: bool | SomeSubstitutions, *,
                 condition: Condition | None = None) -> None:
        super().__init__(value)
        _place(self, condition)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.actions', name, __all__)
