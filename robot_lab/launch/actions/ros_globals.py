"""`<set_parameter>`, `<set_parameters_from_file>`, `<set_remap>`: for later nodes in scope."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, cast

from robot_lab.launch.action import LaunchStep, opt_subs, subs
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.parameters import ParamValue, check_param_file, param_value
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['GlobalRosStep', 'SetUseSimTimeStep']


@register('set_parameter', 'set_parameters_from_file', 'set_remap')
class GlobalRosStep(LaunchStep):
    """set_parameter / set_parameters_from_file / set_remap: for later nodes in scope."""

    def __init__(self, kind: str, first: SomeSubstitutions, second: object = None) -> None:
        self.kind = kind
        self.first = subs(first)
        # a parameter's value (typed when performed), else the remap's target
        self.second = second if kind == 'parameter' else opt_subs(cast(SomeSubstitutions, second))

    def execute(self, context: LaunchContext) -> None:
        if self.kind == 'parameter':
            name = perform(self.first, context)
            value = param_value(self.second, context, name)
            entry: str | tuple[str, object] = (name, value)
            key = 'global_params'
        elif self.kind == 'file':
            path = os.path.abspath(perform(self.first, context))
            check_param_file(path, context)
            entry, key = path, 'global_params'
        else:
            assert isinstance(self.second, list)
            entry = (perform(self.first, context), perform(self.second, context))
            key = 'ros_remaps'
        # launch appends to the list it finds (shared with enclosing scopes): same here
        if context.ros[key] is None:
            context.ros[key] = []
        context.ros[key].append(entry)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        if e.type_name == 'set_parameter':
            return cls('parameter', required(e, 'name'), ParamValue(required(e, 'value')))
        if e.type_name == 'set_parameters_from_file':
            return cls('file', required(e, 'filename'))
        return cls('remap', required(e, 'from'), required(e, 'to'))


@register('set_use_sim_time')
class SetUseSimTimeStep(GlobalRosStep):
    """`<set_use_sim_time value=...>` / SetUseSimTime: `use_sim_time` for later nodes in scope.

    Jazzy's launch_ros sets it on the launcher's own ROS node; robot_lab's launcher has none,
    so it does what the action is used for: every node started after it in its scope gets
    the parameter (as `SetParameter('use_sim_time', value)` does).
    """

    launch_name = 'SetUseSimTime'

    def __init__(self, value: bool | SomeSubstitutions) -> None:
        typed = value if isinstance(value, bool) else ParamValue(subs(value), 'bool')
        super().__init__('parameter', 'use_sim_time', typed)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(required(e, 'value'))
