"""`<executable>`/ExecuteProcess: a command line resolved into a ProcessSpec."""

from __future__ import annotations

import os
import shlex
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from robot_lab.launch.action import LaunchStep, Subs, subs
from robot_lab.launch.actions.event_handlers import EventHandler, RegisterEventHandlerStep, Response
from robot_lab.launch.entity import Entity, env_pairs, split_cmdline, sub_attr
from robot_lab.launch.plan import (
    ProcessSpec,
)
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, coerce, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['ExecuteStep', 'ProcessOptions', 'parse_process_options']

@dataclass
class ProcessOptions:
    """What ExecuteProcess and Node share (launch's ExecuteProcess keyword arguments)."""

    cwd: Subs | None = None
    name: Subs | None = None
    prefix: Subs | None = None
    output: Subs | None = None
    respawn: bool | Subs = False
    respawn_delay: float | None = None
    respawn_max_retries: int = -1
    sigterm_timeout: float | SomeSubstitutions = 5.0
    sigkill_timeout: float | SomeSubstitutions = 5.0
    shell: bool = False
    on_exit: str | None = None
    # on_exit=[actions] or a function(event, context): an OnProcessExit handler on itself
    on_exit_handler: Response = None
    env: list[tuple[Subs, Subs]] | None = None
    additional_env: list[tuple[Subs, Subs]] = field(default_factory=list)


@register('executable')
class ExecuteStep(LaunchStep):
    """`<executable>` / ExecuteProcess."""

    launch_name = 'ExecuteProcess'

    def __init__(self, cmd: Sequence[SomeSubstitutions], options: ProcessOptions) -> None:
        self.cmd = [subs(part) for part in cmd]
        self.options = options

    def _spec(self, context: LaunchContext, cmd: list[str], **extra: Any) -> ProcessSpec:
        opts = self.options
        if opts.prefix is not None:
            prefix = perform(opts.prefix, context)
        else:
            prefix = context.configurations.get('launch-prefix', '')
        if prefix:
            cmd = [*shlex.split(prefix), *cmd]
        if opts.env is not None:
            env = {perform(k, context): perform(v, context) for k, v in opts.env}
        else:
            env = dict(context.environment)
        for key, value in opts.additional_env:
            env[perform(key, context)] = perform(value, context)
        label = perform(opts.name, context) if opts.name is not None else os.path.basename(cmd[0])
        output = perform(opts.output, context) if opts.output is not None else 'log'
        respawn = opts.respawn if isinstance(opts.respawn, bool) else coerce(
            perform(opts.respawn, context), 'bool')
        return ProcessSpec(
            cmd=cmd, label=label, env=env,
            cwd=perform(opts.cwd, context) if opts.cwd is not None else None,
            output=output, respawn=bool(respawn),
            respawn_delay=float(opts.respawn_delay or 0.0),
            respawn_max_retries=int(opts.respawn_max_retries),
            on_exit=opts.on_exit,
            sigterm_timeout=float(perform(subs(str(opts.sigterm_timeout)), context)
                                  if not isinstance(opts.sigterm_timeout, float | int)
                                  else opts.sigterm_timeout),
            sigkill_timeout=float(perform(subs(str(opts.sigkill_timeout)), context)
                                  if not isinstance(opts.sigkill_timeout, float | int)
                                  else opts.sigkill_timeout),
            shell=opts.shell,
            source=context.where(),
            origin=self,
            **extra,
        )

    def execute(self, context: LaunchContext) -> None:
        cmd = [perform(part, context) for part in self.cmd]
        if not cmd or not cmd[0]:
            raise context.error('empty command line', fix='give cmd="program args..."')
        spec = self._spec(context, cmd, executable=os.path.basename(cmd[0]))
        context.sink.append(spec)
        self.register_on_exit(context)

    def register_on_exit(self, context: LaunchContext) -> None:
        """`on_exit=[...]`: launch registers an OnProcessExit handler for this action."""
        if self.options.on_exit_handler is None:
            return
        handler = EventHandler('process_exit', self, {'on_exit': self.options.on_exit_handler})
        RegisterEventHandlerStep(handler).execute(context)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        cmd = e.attr('cmd', optional=False)
        return cls(split_cmdline(cmd), parse_process_options(e))


def parse_process_options(entity: Entity) -> ProcessOptions:
    options = ProcessOptions()
    options.cwd = sub_attr(entity, 'cwd')
    options.name = sub_attr(entity, 'name')
    on_exit = entity.attr('on_exit')
    if on_exit is not None:
        if on_exit != 'shutdown':
            raise ValueError(
                f'Attribute on_exit of Entity node expected to be shutdown but got `{on_exit}`'
                'Other on_exit actions not yet supported')
        options.on_exit = 'shutdown'
    options.prefix = sub_attr(entity, 'launch-prefix')
    options.output = sub_attr(entity, 'output')
    respawn = sub_attr(entity, 'respawn')
    options.respawn = respawn if respawn is not None else False
    retries = entity.attr('respawn_max_retries', 'int')
    if retries is not None:
        options.respawn_max_retries = retries
    for key in ('respawn_delay', 'sigkill_timeout', 'sigterm_timeout'):
        value = entity.attr(key, 'float')
        if value is not None:
            if value < 0.0:
                raise ValueError(f'Attribute {key} of Entity node expected to be a '
                                 f'non-negative value but got `{value}`')
            setattr(options, key, value)
    shell = entity.attr('shell', 'bool')
    options.shell = bool(shell)
    entity.attr('emulate_tty', 'bool')  # accepted; children get pipes either way
    options.additional_env = env_pairs(entity) or []
    return options
