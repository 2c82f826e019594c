"""launch.actions: robot_lab's launch actions with launch's constructor signatures."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, NoReturn

from robot_lab.launch.action import LaunchEntity, LaunchStep, Subs, as_step, subs
from robot_lab.launch.action import opt_subs as opt
from robot_lab.launch.actions.arguments import (
    DeclareArgumentStep,
    ResetConfigurationsStep,
    ScopeStep,
    SetConfigurationStep,
    UnsetConfigurationStep,
)
from robot_lab.launch.actions.environment import EnvironmentStep
from robot_lab.launch.actions.event_handlers import (
    EmitEventStep,
    EventHandler,
    RegisterEventHandlerStep,
    Response,
)
from robot_lab.launch.actions.execute_process import ExecuteStep, ProcessOptions
from robot_lab.launch.actions.group import GroupStep
from robot_lab.launch.actions.include import IncludeStep
from robot_lab.launch.actions.log import LogStep
from robot_lab.launch.actions.opaque import OpaqueCallable, OpaqueStep
from robot_lab.launch.actions.shutdown import ShutdownStep
from robot_lab.launch.actions.timer import TimerStep
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.conditions import Condition
from robot_lab.launch.substitutions import SomeSubstitutions

from .launch_description_sources import Located

__all__ = [
    'AppendEnvironmentVariable',
    'DeclareLaunchArgument',
    'EmitEvent',
    'ExecuteProcess',
    'GroupAction',
    'IncludeLaunchDescription',
    'LogInfo',
    'OpaqueFunction',
    'PopEnvironment',
    'PopLaunchConfigurations',
    'PushEnvironment',
    'PushLaunchConfigurations',
    'RegisterEventHandler',
    'ResetEnvironment',
    'ResetLaunchConfigurations',
    'SetEnvironmentVariable',
    'SetLaunchConfiguration',
    'Shutdown',
    'TimerAction',
    'UnsetEnvironmentVariable',
    'UnsetLaunchConfiguration',
]


def _place(step: LaunchStep, condition: Condition | None) -> None:
    step.condition = condition
    step.locate_caller()


def to_step(entity: LaunchEntity) -> LaunchStep:
    """An action or a (nested) LaunchDescription."""
    return as_step(entity)


class DeclareLaunchArgument(DeclareArgumentStep):
    def __init__(self, name: str, *, default_value: SomeSubstitutions | None = None,
                 description: str | None = None,
                 choices: Sequence[str] | None = None, condition: Condition | None = None,
                 **_: object) -> None:
        super().__init__(name, default_value, description or '', choices)
        _place(self, condition)

    @property
    def default_value(self) -> Subs | None:
        return self.default


class SetLaunchConfiguration(SetConfigurationStep):
    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions, *,
                 condition: Condition | None = None) -> None:
        super().__init__(name, value)
        _place(self, condition)


class IncludeLaunchDescription(IncludeStep):
    def __init__(self, launch_description_source: Located | SomeSubstitutions,
                 *, launch_arguments: Iterable[tuple[SomeSubstitutions, SomeSubstitutions]]
                 | Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
                 condition: Condition | None = None, **_: object) -> None:
        location = (launch_description_source.location
                    if isinstance(launch_description_source, Located)
                    else launch_description_source)
        pairs = launch_arguments.items() if isinstance(launch_arguments, Mapping) \
            else (launch_arguments or [])
        super().__init__(location, list(pairs))
        _place(self, condition)


class GroupAction(GroupStep):
    def __init__(self, actions: Iterable[LaunchEntity], *, scoped: bool = True,
                 forwarding: bool = True,
                 launch_configurations: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
                 condition: Condition | None = None, **_: object) -> None:
        super().__init__([to_step(a) for a in actions], scoped, forwarding, launch_configurations)
        _place(self, condition)


def process_options(
    *, name: SomeSubstitutions | None = None, cwd: SomeSubstitutions | None = None,
    env: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
    additional_env: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
    shell: bool = False, sigterm_timeout: float | SomeSubstitutions = 5.0,
    sigkill_timeout: float | SomeSubstitutions = 5.0, prefix: SomeSubstitutions | None = None,
    output: SomeSubstitutions = 'log', respawn: bool | SomeSubstitutions = False,
    respawn_delay: float | None = None, respawn_max_retries: int = -1,
    on_exit: Response = None, **_: object,
) -> ProcessOptions:
    """ExecuteProcess's keyword arguments (emulate_tty, output_format, ... are accepted)."""
    exit_action, exit_handler = None, None
    if on_exit is not None:
        actions = on_exit if isinstance(on_exit, list | tuple) else [on_exit]
        if all(isinstance(a, ShutdownStep) and a.condition is None for a in actions):
            exit_action = 'shutdown'
        else:
            exit_handler = on_exit  # actions, or a function(event, context)
    return ProcessOptions(
        cwd=opt(cwd), name=opt(name), prefix=opt(prefix), output=opt(output),
        respawn=respawn if isinstance(respawn, bool) else subs(respawn),
        respawn_delay=respawn_delay, respawn_max_retries=respawn_max_retries,
        sigterm_timeout=sigterm_timeout, sigkill_timeout=sigkill_timeout, shell=shell,
        on_exit=exit_action, on_exit_handler=exit_handler,
        env=None if env is None else [(subs(k), subs(v)) for k, v in env.items()],
        additional_env=[(subs(k), subs(v)) for k, v in (additional_env or {}).items()],
    )


class ExecuteProcess(ExecuteStep):
    def __init__(self, *, cmd: Iterable[SomeSubstitutions], condition: Condition | None = None,
                 **kwargs: Any) -> None:
        super().__init__([subs(part) for part in cmd], process_options(**kwargs))
        _place(self, condition)


class TimerAction(TimerStep):
    def __init__(self, *, period: float | SomeSubstitutions, actions: Iterable[LaunchEntity],
                 condition: Condition | None = None, **_: object) -> None:
        super().__init__(period if isinstance(period, float | int) else subs(period),
                         [to_step(a) for a in actions])
        _place(self, condition)


class LogInfo(LogStep):
    def __init__(self, *, msg: SomeSubstitutions, condition: Condition | None = None,
                 **_: object) -> None:
        super().__init__(msg)
        _place(self, condition)


class SetEnvironmentVariable(EnvironmentStep):
    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions, *,
                 condition: Condition | None = None) -> None:
        super().__init__('set', name, value)
        _place(self, condition)


class UnsetEnvironmentVariable(EnvironmentStep):
    def __init__(self, name: SomeSubstitutions, *, condition: Condition | None = None) -> None:
        super().__init__('unset', name)
        _place(self, condition)


class AppendEnvironmentVariable(EnvironmentStep):
    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions, *,
                 prepend: bool | SomeSubstitutions = False,
                 separator: SomeSubstitutions = os.pathsep,
                 condition: Condition | None = None) -> None:
        super().__init__('append', name, value, prepend, separator)
        _place(self, condition)


class OpaqueFunction(OpaqueStep):
    def __init__(self, *, function: OpaqueCallable, args: Sequence[object] | None = None,
                 kwargs: Mapping[str, object] | None = None,
                 condition: Condition | None = None) -> None:
        super().__init__(function, args, kwargs)
        _place(self, condition)


class Shutdown(ShutdownStep):
    def __init__(self, *, reason: SomeSubstitutions = 'reason not given',
                 condition: Condition | None = None) -> None:
        super().__init__(reason)
        _place(self, condition)


class RegisterEventHandler(RegisterEventHandlerStep):
    def __init__(self, event_handler: EventHandler, *, condition: Condition | None = None,
                 **_: object) -> None:
        super().__init__(event_handler)
        _place(self, condition)


class EmitEvent(EmitEventStep):
    def __init__(self, *, event: object, condition: Condition | None = None, **_: object) -> None:
        super().__init__(event)
        _place(self, condition)


class ResetLaunchConfigurations(ResetConfigurationsStep):
    def __init__(self, launch_configurations: Mapping[SomeSubstitutions, SomeSubstitutions]
                 | None = None, *,
                 condition: Condition | None = None) -> None:
        super().__init__(launch_configurations)
        _place(self, condition)


class UnsetLaunchConfiguration(UnsetConfigurationStep):
    def __init__(self, name: SomeSubstitutions, *, condition: Condition | None = None) -> None:
        super().__init__(name)
        _place(self, condition)


class PushLaunchConfigurations(ScopeStep):
    def __init__(self, *, condition: Condition | None = None) -> None:
        super().__init__('push', 'configurations')
        _place(self, condition)


class PopLaunchConfigurations(ScopeStep):
    def __init__(self, *, condition: Condition | None = None) -> None:
        super().__init__('pop', 'configurations')
        _place(self, condition)


class PushEnvironment(ScopeStep):
    def __init__(self, *, condition: Condition | None = None) -> None:
        super().__init__('push', 'environment')
        _place(self, condition)


class PopEnvironment(ScopeStep):
    def __init__(self, *, condition: Condition | None = None) -> None:
        super().__init__('pop', 'environment')
        _place(self, condition)


class ResetEnvironment(ScopeStep):
    def __init__(self, *, condition: Condition | None = None) -> None:
        super().__init__('reset', 'environment')
        _place(self, condition)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.actions', name, __all__)
