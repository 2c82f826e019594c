"""Launch files -> one LaunchPlan, with launch/launch_ros semantics and nothing started.

Like ros2/launch this runs in two phases: a frontend (XML, YAML or Python) *parses* a file
into actions (so an unknown tag or attribute anywhere is an error, even in a branch that
is switched off), then the actions are *executed* here against a LaunchContext (launch
configurations, environment, ROS namespace, global parameters and remaps, with scopes).
Executing a process action does not start it: it resolves its full command line into a
ProcessSpec. Every problem is a LaunchError (or ParamFileError) with the file and line.
"""

from __future__ import annotations

import inspect
import os
import re
import shlex
import tempfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robot_lab.errors import LaunchError, ParamFileError, RobotLabError
from robot_lab.launch.description import (
    Action,
    LaunchArgument,
    LaunchPlan,
    LogAction,
    ProcessSpec,
    ShutdownAction,
    TimerAction,
)
from robot_lab.launch.substitutions import (
    Substitution,
    SubstitutionFailure,
    Text,
    coerce,
    condition_value,
    parse_substitution,
    perform,
)
from robot_lab.params import load_param_file, write_param_file

__all__ = [
    'LaunchContext',
    'describe_launch',
    'find_launch_file',
    'launch_arguments',
    'parse_launch_arguments',
]

Subs = list[Substitution]
_NODE_NAME = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')
_NS_TOKEN = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')
_NOT_SHARE = {'build', 'install', 'log', '__pycache__', 'node_modules'}


# ---------------------------------------------------------------------------- context


class LaunchContext:
    """The state actions read and change, with scopes pushed and popped by groups."""

    def __init__(self, arguments: Mapping[str, str], environment: Mapping[str, str]) -> None:
        self.configurations: dict[str, str] = dict(arguments)
        self.environment: dict[str, str] = dict(environment)
        self.initial_environment = dict(environment)
        # launch keeps these three in its launch configurations; so do we (scoped the same)
        self.ros: dict[str, Any] = {'ros_namespace': None, 'global_params': None,
                                    'ros_remaps': None}
        self._scopes: list[tuple[dict[str, str], dict[str, Any], dict[str, str]]] = []
        self.files: list[Path] = []
        self.sink: list[Action] = []
        self.arguments: list[LaunchArgument] = []
        self.source: tuple[Path | None, int | None] = (None, None)
        self._file_override: Path | None = None

    # what substitutions and OpaqueFunctions see
    @property
    def current_file(self) -> Path | None:
        return self._file_override or (self.files[-1] if self.files else None)

    @property
    def launch_configurations(self) -> dict[str, str]:
        return self.configurations

    def perform_substitution(self, substitution: Substitution) -> str:
        return substitution.perform(self)

    def push(self) -> None:
        self._scopes.append((dict(self.configurations), dict(self.ros), dict(self.environment)))

    def pop(self) -> None:
        self.configurations, self.ros, self.environment = self._scopes.pop()

    def where(self) -> str | None:
        """'file:line' of the action being executed, for ProcessSpec.source and friends."""
        file, line = self.source
        if file is None:
            return None
        return str(file) if line is None else f'{file}:{line}'

    def error(self, message: str, fix: str | None = None) -> LaunchError:
        file, line = self.source
        return LaunchError(message, file=file, line=line, fix=fix)

    def run(self, actions: Iterable[LaunchStep]) -> None:
        for action in actions:
            self.run_one(action)

    def run_one(self, action: LaunchStep) -> None:
        previous, previous_file = self.source, self._file_override
        self.source = (action.file or self.current_file, action.line)
        self._file_override = action.file
        try:
            if action.condition is None or action.condition.evaluate(self):
                action.execute(self)
        except RobotLabError as err:
            if isinstance(err, LaunchError | ParamFileError) or err.file is not None:
                raise
            raise self.error(err.message, err.fix) from None
        except (SubstitutionFailure, ValueError, TypeError, RuntimeError, OSError) as err:
            raise self.error(str(err)) from None
        finally:
            self.source, self._file_override = previous, previous_file


def _subs(value: Any) -> Subs:
    """SomeSubstitutionsType (str, Substitution or a list of them) -> list of substitutions."""
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, str):
        return [Text(value)]
    if isinstance(value, os.PathLike):
        return [Text(os.fspath(value))]
    if isinstance(value, Iterable):
        out: Subs = []
        for item in value:
            out.extend(_subs(item))
        return out
    raise TypeError(f'expected text or substitutions, got {type(value).__name__}: {value!r}')


def _opt_subs(value: Any) -> Subs | None:
    return None if value is None else _subs(value)


# ------------------------------------------------------------------------- conditions


class Condition:
    """IfCondition / UnlessCondition: 'true'/'1' or 'false'/'0', else an error."""

    def __init__(self, expression: Any, negate: bool = False) -> None:
        self.expression = _subs(expression)
        self.negate = negate

    def evaluate(self, context: LaunchContext) -> bool:
        return condition_value(perform(self.expression, context)) != self.negate


class EqualsCondition(Condition):
    """LaunchConfigurationEquals / NotEquals."""

    def __init__(self, name: str, value: Any, negate: bool = False) -> None:
        self.name, self.value, self.negate = name, _opt_subs(value), negate

    def evaluate(self, context: LaunchContext) -> bool:
        value = None if self.value is None else perform(self.value, context)
        return (context.configurations.get(self.name) == value) != self.negate


# ---------------------------------------------------------------------------- actions


def _caller_line() -> tuple[Path | None, int | None]:
    """file:line of the first frame outside robot_lab's launch package (a Python launch file)."""
    here = str(Path(__file__).parent)
    for frame in inspect.stack(0)[2:]:
        if not frame.filename.startswith(here):
            return Path(frame.filename), frame.lineno
    return None, None


class LaunchStep:
    """A parsed action; `execute` resolves it into the plan (and may change the context)."""

    file: Path | None = None
    line: int | None = None
    condition: Condition | None = None

    def locate(self, file: Path | None, line: int | None) -> None:
        self.file, self.line = file, line

    def locate_caller(self) -> None:
        self.file, self.line = _caller_line()

    def execute(self, context: LaunchContext) -> None:
        raise NotImplementedError

    def children(self) -> list[LaunchStep]:
        return []


class DescriptionStep(LaunchStep):
    """A LaunchDescription: its entities, in order, in the current scope."""

    def __init__(self, entities: Sequence[LaunchStep]) -> None:
        self.entities = list(entities)

    def execute(self, context: LaunchContext) -> None:
        context.run(self.entities)

    def children(self) -> list[LaunchStep]:
        return self.entities


class DeclareArgumentStep(LaunchStep):
    def __init__(self, name: str, default: Any = None, description: str = '',
                 choices: Sequence[str] | None = None) -> None:
        self.name = name
        self.default = _opt_subs(default)
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


class SetConfigurationStep(LaunchStep):
    """`<let>` / SetLaunchConfiguration."""

    def __init__(self, name: Any, value: Any) -> None:
        self.name, self.value = _subs(name), _subs(value)

    def execute(self, context: LaunchContext) -> None:
        context.configurations[perform(self.name, context)] = perform(self.value, context)


class GroupStep(LaunchStep):
    """`<group>` / GroupAction: scoped by default (configurations and environment)."""

    def __init__(self, actions: Sequence[LaunchStep], scoped: bool = True, forwarding: bool = True,
                 keep: Mapping[Any, Any] | None = None) -> None:
        self.actions = list(actions)
        self.scoped, self.forwarding = scoped, forwarding
        self.keep = [(_subs(k), _subs(v)) for k, v in (keep or {}).items()]

    def execute(self, context: LaunchContext) -> None:
        if not self.scoped:
            for name, value in self.keep:
                context.configurations[perform(name, context)] = perform(value, context)
            context.run(self.actions)
            return
        context.push()
        try:
            kept = {perform(n, context): perform(v, context) for n, v in self.keep}
            if not self.forwarding:
                context.configurations = {}
                context.ros = {key: None for key in context.ros}
                context.environment = dict(context.initial_environment)
            context.configurations.update(kept)
            context.run(self.actions)
        finally:
            context.pop()

    def children(self) -> list[LaunchStep]:
        return self.actions


class IncludeStep(LaunchStep):
    """`<include>` / IncludeLaunchDescription: not scoped; arguments become configurations."""

    def __init__(self, path: Any, arguments: Iterable[tuple[Any, Any]] = (),
                 loader: Callable[[Path], DescriptionStep] | None = None) -> None:
        self.path = _subs(path)
        self.arguments = [(_subs(n), _subs(v)) for n, v in arguments]
        self.loader = loader

    def execute(self, context: LaunchContext) -> None:
        path = Path(os.path.abspath(perform(self.path, context)))
        if not path.is_file():
            raise context.error(f'included launch file not found: {path}',
                                fix='check the path; relative paths resolve against the '
                                'current directory, use $(dirname)/file for a sibling file')
        chain = [*context.files, path]
        if path in context.files:
            cycle = ' -> '.join(p.name for p in chain[chain.index(path):])
            raise context.error(f'include cycle: {cycle}',
                                fix='remove one of the includes (or guard it with if=)')
        names = [perform(n, context) for n, _ in self.arguments]
        values = [perform(v, context) for _, v in self.arguments]
        description = (self.loader or load_description)(path)
        given = set(names)
        for declared in _declared(description, conditional_ok=False):
            if declared.default is None and declared.name not in given:
                raise context.error(
                    f"Included launch description missing required argument '{declared.name}' "
                    f"(description: '{declared.description}'), given: [{', '.join(names)}]",
                    fix=f'add <arg name="{declared.name}" value="..."/> to the include')
        context.configurations.update(zip(names, values, strict=True))
        context.files.append(path)
        try:
            context.run([description])
        finally:
            context.files.pop()


class PushNamespaceStep(LaunchStep):
    """`<push-ros-namespace>` / PushROSNamespace: relative values nest, absolute replace."""

    def __init__(self, namespace: Any) -> None:
        self.namespace = _subs(namespace)

    def execute(self, context: LaunchContext) -> None:
        pushed = perform(self.namespace, context)
        previous = context.ros['ros_namespace']
        namespace = _absolute(_prefix_namespace(previous, pushed))
        assert namespace is not None
        problem = _namespace_problem(namespace)
        if problem:
            raise context.error(
                f"The resulting namespace is invalid: [previous_namespace='{previous}', "
                f"pushed_namespace='{pushed}'] ({problem})")
        context.ros['ros_namespace'] = namespace


class EnvironmentStep(LaunchStep):
    """set_env / unset_env / append_env."""

    def __init__(self, kind: str, name: Any, value: Any = '', prepend: Any = False,
                 separator: Any = os.pathsep) -> None:
        self.kind, self.name, self.value = kind, _subs(name), _subs(value)
        self.prepend = prepend if isinstance(prepend, bool) else _subs(prepend)
        self.separator = _subs(separator)

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


class GlobalRosStep(LaunchStep):
    """set_parameter / set_parameters_from_file / set_remap: for later nodes in scope."""

    def __init__(self, kind: str, first: Any, second: Any = None) -> None:
        self.kind = kind
        self.first = _subs(first)
        self.second = second if kind == 'parameter' else _opt_subs(second)

    def execute(self, context: LaunchContext) -> None:
        if self.kind == 'parameter':
            name = perform(self.first, context)
            value = _param_value(self.second, context, name)
            entry: Any = (name, value)
            key = 'global_params'
        elif self.kind == 'file':
            path = os.path.abspath(perform(self.first, context))
            _check_param_file(path, context)
            entry, key = path, 'global_params'
        else:
            assert self.second is not None
            entry = (perform(self.first, context), perform(self.second, context))
            key = 'ros_remaps'
        # launch appends to the list it finds (shared with enclosing scopes): same here
        if context.ros[key] is None:
            context.ros[key] = []
        context.ros[key].append(entry)


@dataclass
class ParamValue:
    """A parameter value: a Python value, or substitutions typed by `value_type` (None=YAML)."""

    value: Any
    value_type: str | None = None


@dataclass
class ParamFileRef:
    """A `from=` / ParameterFile parameter file."""

    path: Subs
    allow_substs: bool = False


@dataclass
class ProcessOptions:
    """What ExecuteProcess and Node share (launch's ExecuteProcess keyword arguments)."""

    cwd: Subs | None = None
    name: Subs | None = None
    prefix: Subs | None = None
    output: Subs | None = None
    respawn: Any = False
    respawn_delay: float | None = None
    respawn_max_retries: int = -1
    sigterm_timeout: Any = 5.0
    sigkill_timeout: Any = 5.0
    shell: bool = False
    on_exit: str | None = None
    env: list[tuple[Subs, Subs]] | None = None
    additional_env: list[tuple[Subs, Subs]] = field(default_factory=list)


class ExecuteStep(LaunchStep):
    """`<executable>` / ExecuteProcess."""

    def __init__(self, cmd: Sequence[Any], options: ProcessOptions) -> None:
        self.cmd = [_subs(part) for part in cmd]
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
            sigterm_timeout=float(perform(_subs(str(opts.sigterm_timeout)), context)
                                  if not isinstance(opts.sigterm_timeout, float | int)
                                  else opts.sigterm_timeout),
            sigkill_timeout=float(perform(_subs(str(opts.sigkill_timeout)), context)
                                  if not isinstance(opts.sigkill_timeout, float | int)
                                  else opts.sigkill_timeout),
            shell=opts.shell,
            source=context.where(),
            **extra,
        )

    def execute(self, context: LaunchContext) -> None:
        cmd = [perform(part, context) for part in self.cmd]
        if not cmd or not cmd[0]:
            raise context.error('empty command line', fix='give cmd="program args..."')
        spec = self._spec(context, cmd, executable=os.path.basename(cmd[0]))
        context.sink.append(spec)


def _prefix_namespace(base: str | None, namespace: str | None) -> str | None:
    """launch_ros's prefix_namespace: relative namespaces nest, absolute ones replace."""
    if base is None and namespace is None:
        return None
    if namespace is None:
        combined = base
    elif not base or namespace.startswith('/'):
        combined = namespace
    else:
        combined = ('' if base == '/' else base) + '/' + namespace
    assert combined is not None
    return combined if combined == '/' else combined.rstrip('/')


def _absolute(namespace: str | None) -> str | None:
    if namespace is None:
        return None
    return namespace if namespace.startswith('/') else '/' + namespace


def _namespace_problem(namespace: str) -> str | None:
    """rcl's namespace rules, as rclpy.validate_namespace applies them."""
    if namespace == '/':
        return None
    if not namespace.startswith('/'):
        return 'namespace must be absolute'
    if namespace.endswith('/'):
        return "namespace must not end with '/'"
    if '//' in namespace:
        return "namespace must not contain repeated '/'"
    for token in namespace[1:].split('/'):
        if not _NS_TOKEN.fullmatch(token):
            if token[:1].isdigit():
                return f"namespace token '{token}' must not start with a number"
            return f"namespace token '{token}' must contain only alphanumerics and '_'"
    return None


def _node_name_problem(name: str) -> str | None:
    if not name:
        return 'node name must not be empty'
    if name[0].isdigit():
        return 'node name must not start with a number'
    if not _NODE_NAME.fullmatch(name):
        return "node name must not contain characters other than alphanumerics or '_'"
    return None


def _substituted_param_file(path: str, context: LaunchContext) -> str:
    """`allow_substs`: the file with its `$(...)` performed, in a launch_params_ file."""
    try:
        text = perform(parse_substitution(Path(path).read_text()), context)
    except FileNotFoundError:
        raise context.error(f'parameter file not found: {path}') from None
    try:
        yaml.safe_load(text)
    except yaml.YAMLError:
        raise context.error('The substituted parameter file is not a valid yaml file') from None
    with tempfile.NamedTemporaryFile('w', prefix='launch_params_', delete=False) as handle:
        handle.write(text)
    return handle.name


def _check_param_file(path: str, context: LaunchContext) -> None:
    """rcl would refuse the file inside the node, after start; refuse it now, located."""
    try:
        load_param_file(path)
    except ParamFileError as err:
        used = context.where()
        where = f' (used at {used})' if used else ''
        raise ParamFileError(err.message + where, file=err.file, line=err.line,
                             fix=err.fix) from None


def _is_subs(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and \
        all(isinstance(x, Substitution) for x in value)


def _param_value(value: Any, context: LaunchContext, name: str) -> Any:
    """launch_ros's evaluation of one parameter value.

    Substitutions are performed, then typed by `value_type` (None: YAML rules); literal
    values are already typed (the XML frontend coerced them, YAML and Python give them).
    """
    if isinstance(value, ParamValue):
        raw, value_type = value.value, value.value_type
    else:
        raw, value_type = value, None
    item_type = value_type[len('list_of_'):] if value_type and value_type.startswith(
        'list_of_') else None
    if isinstance(raw, Substitution):
        raw = [raw]
    try:
        if _is_subs(raw):
            text = perform(raw, context)
            if value_type is None and not text:
                return ''
            result = coerce(text, value_type)
            return _uniform(result, name) if isinstance(result, list) else result
        if isinstance(raw, list | tuple):
            items = []
            for item in raw:
                if isinstance(item, Substitution) or _is_subs(item):
                    item = coerce(perform(_subs(item), context), item_type)
                elif isinstance(item, str) and item_type is not None:
                    item = coerce(item, item_type)
                items.append(item)
            if all(isinstance(x, int | float) and not isinstance(x, bool) for x in items) and \
                    (item_type == 'float' or any(isinstance(x, float) for x in items)):
                items = [float(x) for x in items]
            return _uniform(items, name)
        if isinstance(raw, str) and value_type not in (None, 'str', 'yaml'):
            return coerce(raw, value_type)
    except ValueError as err:
        raise ValueError(f'parameter {name}: {err}') from None
    if isinstance(raw, bool | int | float | str | bytes):
        return raw
    raise TypeError(f'Unexpected type for parameter value {raw!r}')


def _uniform(items: list[Any], name: str) -> list[Any]:
    if not items or any(type(x) is not type(items[0]) for x in items) or \
            type(items[0]) not in (bool, int, float, str):
        raise TypeError(
            'Expected a non-empty sequence, with items of uniform type. Allowed sequence item '
            f'types are bool, int, float, str. Got inconsistent input for "{name}"')
    return items


def _flatten(params: Mapping[Any, Any], context: LaunchContext,
             prefix: str = '') -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = perform(_subs(key), context)
        full = f'{prefix}.{name}' if prefix else name
        if isinstance(value, Mapping):
            out.update(_flatten(value, context, full))
        else:
            out[full] = _param_value(value, context, full)
    return out


class NodeStep(ExecuteStep):
    """`<node>` / launch_ros.actions.Node: the command line launch_ros builds."""

    def __init__(self, executable: Any, package: Any = None, name: Any = None,
                 namespace: Any = None, exec_name: Any = None,
                 parameters: Sequence[Any] | None = None,
                 remappings: Iterable[tuple[Any, Any]] | None = None,
                 ros_arguments: Sequence[Any] | None = None,
                 arguments: Sequence[Any] | None = None,
                 options: ProcessOptions | None = None) -> None:
        options = options or ProcessOptions()
        if exec_name is not None:
            options.name = _subs(exec_name)
        super().__init__([], options)
        self.executable = _subs(executable)
        self.package = _opt_subs(package)
        self.name = _opt_subs(name)
        self.namespace = _opt_subs(namespace)
        self.parameters = list(parameters or [])
        self.remappings = [(_subs(a), _subs(b)) for a, b in (remappings or [])]
        self.ros_arguments = None if ros_arguments is None else [_subs(a) for a in ros_arguments]
        self.arguments = [_subs(a) for a in (arguments or [])]

    def execute(self, context: LaunchContext) -> None:
        executable = perform(self.executable, context)
        package = perform(self.package, context) if self.package is not None else None
        if package is not None:
            from robot_lab.pkg.index import find_executable

            path = str(find_executable(package, executable, context.environment))
        else:
            path = executable
        cmd = [path, *(perform(a, context) for a in self.arguments)]
        if self.ros_arguments is not None:
            cmd += ['--ros-args', *(perform(a, context) for a in self.ros_arguments)]
        cmd.append('--ros-args')
        name = None
        if self.name is not None:
            name = perform(self.name, context)
            problem = _node_name_problem(name)
            if problem:
                raise context.error(f"Invalid node name '{name}': {problem}")
            cmd += ['-r', f'__node:={name}']
        namespace = _absolute(_prefix_namespace(
            context.ros['ros_namespace'],
            perform(self.namespace, context) if self.namespace is not None else None))
        if namespace is not None:
            problem = _namespace_problem(namespace)
            if problem:
                raise context.error(f"Invalid namespace '{namespace}': {problem}")
            cmd += ['-r', f'__ns:={namespace}']
        # launch_ros keys name/value files by the node's full name only when both name and
        # namespace are known; otherwise ('/**') they reach every node of the process
        fqn = _prefix_namespace(namespace, name) if name is not None and namespace else None
        param_files: list[str] = []
        for entry in context.ros['global_params'] or []:
            if isinstance(entry, tuple):
                cmd += ['-p', f'{entry[0]}:={entry[1]}']
            else:
                cmd += ['--params-file', entry]
                param_files.append(entry)
        for entry in self.parameters:
            if isinstance(entry, ParamFileRef):
                file = str(Path(perform(entry.path, context)))  # as ParameterFile.evaluate
                if entry.allow_substs:
                    file = _substituted_param_file(file, context)
                _check_param_file(file, context)
                cmd += ['--params-file', file]
                param_files.append(file)
            elif isinstance(entry, Mapping):
                values = _flatten(entry, context)
                written = write_param_file(values, fqn or '/**')
                cmd += ['--params-file', str(written)]
                param_files.append(str(written))
            else:
                raise context.error(f'invalid normalized parameters {entry!r}')
        remaps = list(context.ros['ros_remaps'] or [])
        remaps += [(perform(a, context), perform(b, context)) for a, b in self.remappings]
        for src, dst in remaps:
            cmd += ['-r', f'{src}:={dst}']
        full_name = None
        if name is not None:
            full_name = _prefix_namespace(namespace or '/', name)
        spec = self._spec(context, cmd, node_name=full_name, package=package,
                          executable=executable, param_files=param_files)
        context.sink.append(spec)


class TimerStep(LaunchStep):
    """`<timer period>` / TimerAction: its actions resolved now, started later."""

    def __init__(self, period: Any, actions: Sequence[LaunchStep]) -> None:
        self.period = period if isinstance(period, float | int) else _subs(period)
        self.actions = list(actions)

    def execute(self, context: LaunchContext) -> None:
        period = float(self.period if isinstance(self.period, float | int)
                       else perform(self.period, context))
        outer = context.sink
        context.sink = []
        try:
            context.run(self.actions)
            inner = context.sink
        finally:
            context.sink = outer
        outer.append(TimerAction(period, inner, source=context.where()))

    def children(self) -> list[LaunchStep]:
        return self.actions


class LogStep(LaunchStep):
    def __init__(self, message: Any, level: str = 'INFO') -> None:
        self.message, self.level = _subs(message), level

    def execute(self, context: LaunchContext) -> None:
        context.sink.append(LogAction(perform(self.message, context), self.level,
                                      source=context.where()))


class ShutdownStep(LaunchStep):
    def __init__(self, reason: Any = '') -> None:
        self.reason = _subs(reason)

    def execute(self, context: LaunchContext) -> None:
        context.sink.append(ShutdownAction(perform(self.reason, context),
                                           source=context.where()))


class OpaqueStep(LaunchStep):
    """OpaqueFunction: called with the context; the actions it returns run in place."""

    def __init__(self, function: Callable[..., Any], args: Sequence[Any] | None = None,
                 kwargs: Mapping[str, Any] | None = None) -> None:
        self.function, self.args, self.kwargs = function, list(args or []), dict(kwargs or {})

    def execute(self, context: LaunchContext) -> None:
        from robot_lab.launch.frontend_python import compat_api

        try:
            with compat_api():  # the function may import launch modules or look up packages
                result = self.function(context, *self.args, **self.kwargs)
        except RobotLabError:
            raise
        except Exception as err:
            raise _python_error(err, 'OpaqueFunction') from None
        if result:
            context.run([_as_step(item) for item in result])


def _python_error(err: BaseException, what: str) -> LaunchError:
    """A Python exception from launch-file code, located at its innermost launch-file frame."""
    import traceback

    frames = traceback.extract_tb(err.__traceback__)
    here = str(Path(__file__).parent)
    located = [f for f in frames if not f.filename.startswith(here)]
    frame = located[-1] if located else (frames[-1] if frames else None)
    return LaunchError(
        f'{what} raised {type(err).__name__}: {err}',
        file=frame.filename if frame else None, line=frame.lineno if frame else None)


def _as_step(item: Any) -> LaunchStep:
    if isinstance(item, LaunchStep):
        return item
    entities = getattr(item, 'entities', None)
    if entities is not None:
        return DescriptionStep([_as_step(e) for e in entities])
    raise TypeError(f'not a launch action: {item!r}')


# ------------------------------------------- frontend entities (shared by XML and YAML)


class Entity:
    """One tag of an XML or YAML launch file: attributes, sub-entities, location.

    XML attributes are strings coerced to the type asked for; YAML values are checked,
    not coerced (as launch_xml and launch_yaml do). Reading marks an attribute used, so
    `assert_parsed` can name the ones nobody read.
    """

    type_name: str
    file: Path
    line: int | None

    def attr(self, name: str, kind: str = 'str', optional: bool = True) -> Any:
        raise NotImplementedError

    def entities(self, name: str) -> list[Entity] | None:
        raise NotImplementedError

    def children(self) -> list[Entity]:
        raise NotImplementedError

    def assert_parsed(self) -> None:
        raise NotImplementedError

    def typed_value(self, value: Any, type_name: str | None) -> Any:
        """A `param` value as this frontend types it (YAML: as written, no coercion)."""
        return value

    def fail(self, message: str, fix: str | None = None) -> LaunchError:
        return LaunchError(message, file=self.file, line=self.line, fix=fix)


def split_cmdline(text: str) -> list[Subs]:
    """launch's ExecuteProcess._parse_cmdline: split on spaces, keeping substitutions whole."""
    result: list[Subs] = []
    arg: Subs = []
    for sub in parse_substitution(text):
        if not isinstance(sub, Text):
            arg.append(sub)
            continue
        tokens = shlex.split(sub.text)
        if not tokens:
            result.append(arg)
            arg = []
            continue
        if sub.text[0].isspace() and arg:
            result.append(arg)
            arg = []
        arg.append(Text(tokens[0]))
        if len(tokens) > 1:
            result.append(arg)
            result.extend([Text(t)] for t in tokens[1:-1])
            arg = [Text(tokens[-1])]
        if sub.text[-1].isspace():
            result.append(arg)
            arg = []
    if arg:
        result.append(arg)
    return [a for a in result if a]


def _sub_attr(entity: Entity, name: str, optional: bool = True) -> Subs | None:
    value = entity.attr(name, 'str', optional)
    return None if value is None else parse_substitution(value)


def _req(entity: Entity, name: str) -> Subs:
    value = _sub_attr(entity, name, optional=False)
    assert value is not None
    return value


def _env_pairs(entity: Entity) -> list[tuple[Subs, Subs]] | None:
    items = entity.entities('env')
    if items is None:
        return None
    pairs = [(_req(e, 'name'), _req(e, 'value')) for e in items]
    for e in items:
        e.assert_parsed()
    return pairs


def _process_options(entity: Entity) -> ProcessOptions:
    options = ProcessOptions()
    options.cwd = _sub_attr(entity, 'cwd')
    options.name = _sub_attr(entity, 'name')
    on_exit = entity.attr('on_exit')
    if on_exit is not None:
        if on_exit != 'shutdown':
            raise ValueError(
                f'Attribute on_exit of Entity node expected to be shutdown but got `{on_exit}`'
                'Other on_exit actions not yet supported')
        options.on_exit = 'shutdown'
    options.prefix = _sub_attr(entity, 'launch-prefix')
    options.output = _sub_attr(entity, 'output')
    respawn = _sub_attr(entity, 'respawn')
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
    options.additional_env = _env_pairs(entity) or []
    return options


def _literal_or_subs(value: Any) -> Any:
    if not isinstance(value, str):
        return value
    subs = parse_substitution(value)
    if all(isinstance(sub, Text) for sub in subs):
        return ''.join(sub.perform_text() for sub in subs if isinstance(sub, Text))
    return subs


def _param_entities(items: list[Entity]) -> list[Any]:
    """launch_ros's Node.parse_nested_parameters: one entry per top-level `param`."""

    def nested(entries: list[Entity]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for param in entries:
            name = param.attr('name', optional=False)
            type_name = param.attr('type')
            if type_name is not None and type_name not in (
                    'str', 'bool', 'float', 'int', 'yaml', 'list_of_str', 'list_of_bool',
                    'list_of_float', 'list_of_int'):
                raise ValueError(f"Got invalid type identifier '{type_name}'")
            value = param.attr('value', 'any')
            if value is not None:
                value = param.typed_value(value, type_name)
            children = param.entities('param')
            param.assert_parsed()
            if value is not None and children:
                raise RuntimeError('nested parameters and value attributes are mutually exclusive')
            if type_name is not None and children:
                raise RuntimeError('nested parameters and type attributes are mutually exclusive')
            if value is not None:
                # parse_if_substitutions: text with substitutions is evaluated at launch
                if isinstance(value, list):
                    value = [_literal_or_subs(v) for v in value]
                else:
                    value = _literal_or_subs(value)
                out[name] = ParamValue(value, type_name)
            elif children:
                out[name] = nested(children)
            else:
                raise RuntimeError('either a value attribute or nested params are needed')
        return out

    result: list[Any] = []
    for param in items:
        source = param.attr('from')
        allow = param.attr('allow_substs', 'bool')
        name = param.attr('name', 'str', optional=True) if source is not None else None
        if source is not None and name is not None:
            raise RuntimeError('name and from attributes are mutually exclusive')
        if source is not None:
            param.assert_parsed()
            result.append(ParamFileRef(parse_substitution(source), bool(allow)))
        else:
            if allow is not None:
                raise RuntimeError("'allow_substs' can only be used together with 'from' attribute")
            result.append(nested([param]))
    return result


def _tag_arg(e: Entity) -> LaunchStep:
    choices = e.entities('choice')
    values = None
    if choices is not None:
        values = [c.attr('value', optional=False) for c in choices]
        for c in choices:
            c.assert_parsed()
    return DeclareArgumentStep(e.attr('name', optional=False), _sub_attr(e, 'default'),
                               e.attr('description') or '', values)


def _tag_include(e: Entity) -> LaunchStep:
    args = e.entities('arg') or []
    pairs = [(_req(a, 'name'), _req(a, 'value')) for a in args]
    for a in args:
        a.assert_parsed()
    return IncludeStep(_req(e, 'file'), pairs)


def _tag_group(e: Entity) -> LaunchStep:
    scoped = e.attr('scoped', 'bool')
    forwarding = e.attr('forwarding', 'bool')
    keeps = e.entities('keep') or []
    keep = {tuple(_req(k, 'name')): _req(k, 'value') for k in keeps}
    for k in keeps:
        k.assert_parsed()
    actions = [parse_entity(c) for c in e.children() if c.type_name != 'keep']
    return GroupStep(actions, True if scoped is None else scoped,
                     True if forwarding is None else forwarding,
                     {tuple(k): v for k, v in keep.items()})


def _tag_node(e: Entity) -> LaunchStep:
    options = _process_options(e)
    options.name = None  # on a node, `name` is the node's name; exec_name names the process
    args = e.attr('args')
    ros_args = e.attr('ros_args')
    remaps = e.entities('remap') or []
    pairs = [(_req(r, 'from'), _req(r, 'to')) for r in remaps]
    for r in remaps:
        r.assert_parsed()
    params = e.entities('param')
    return NodeStep(
        _req(e, 'exec'), package=_sub_attr(e, 'pkg'), name=_sub_attr(e, 'name'),
        namespace=_sub_attr(e, 'namespace'), exec_name=_sub_attr(e, 'exec_name'),
        parameters=_param_entities(params) if params is not None else None,
        remappings=pairs,
        ros_arguments=split_cmdline(ros_args) if ros_args is not None else None,
        arguments=split_cmdline(args) if args is not None else None,
        options=options,
    )


def _tag_executable(e: Entity) -> LaunchStep:
    cmd = e.attr('cmd', optional=False)
    return ExecuteStep(split_cmdline(cmd), _process_options(e))


def _tag_timer(e: Entity) -> LaunchStep:
    period = e.attr('period', 'float_or_str', optional=False)
    if isinstance(period, str):
        period = parse_substitution(period)
    e.attr('cancel_on_shutdown', 'bool_or_str')  # timers never outlive the plan here
    return TimerStep(period, [parse_entity(c) for c in e.children()])


def _tag_append_env(e: Entity) -> LaunchStep:
    prepend = e.attr('prepend', 'bool_or_str')
    separator = e.attr('separator')
    return EnvironmentStep('append', _req(e, 'name'), _req(e, 'value'),
                           prepend if isinstance(prepend, bool) else
                           (parse_substitution(prepend) if prepend is not None else False),
                           separator if separator is not None else os.pathsep)


TAGS: dict[str, Callable[[Entity], LaunchStep]] = {
    'arg': _tag_arg,
    'let': lambda e: SetConfigurationStep(_req(e, 'name'), _req(e, 'value')),
    'include': _tag_include,
    'group': _tag_group,
    'push-ros-namespace': lambda e: PushNamespaceStep(_req(e, 'namespace')),
    'push_ros_namespace': lambda e: PushNamespaceStep(_req(e, 'namespace')),
    'set_env': lambda e: EnvironmentStep('set', _req(e, 'name'), _req(e, 'value')),
    'unset_env': lambda e: EnvironmentStep('unset', _req(e, 'name')),
    'append_env': _tag_append_env,
    'node': _tag_node,
    'executable': _tag_executable,
    'set_parameter': lambda e: GlobalRosStep('parameter', _req(e, 'name'),
                                             ParamValue(_req(e, 'value'))),
    'set_parameters_from_file': lambda e: GlobalRosStep('file', _req(e, 'filename')),
    'set_remap': lambda e: GlobalRosStep('remap', _req(e, 'from'), _req(e, 'to')),
    'timer': _tag_timer,
    'log': lambda e: LogStep(_req(e, 'message')),
    'shutdown': lambda e: ShutdownStep(_sub_attr(e, 'reason') or ''),
}


def parse_entity(entity: Entity) -> LaunchStep:
    """One tag -> one action, with `if`/`unless` and unused attributes checked."""
    try:
        parser = TAGS.get(entity.type_name)
        if parser is None:
            raise RuntimeError(f'Unrecognized entity of the type: {entity.type_name}')
        when = entity.attr('if')
        unless = entity.attr('unless')
        if when is not None and unless is not None:
            raise RuntimeError("if and unless conditions can't be used simultaneously")
        step = parser(entity)
        entity.assert_parsed()
    except LaunchError:
        raise
    except (ValueError, TypeError, RuntimeError, AttributeError, SubstitutionFailure) as err:
        raise entity.fail(str(err)) from None
    if when is not None:
        step.condition = Condition(parse_substitution(when))
    elif unless is not None:
        step.condition = Condition(parse_substitution(unless), negate=True)
    step.locate(entity.file, entity.line)
    return step


def parse_root(root: Entity) -> DescriptionStep:
    if root.type_name != 'launch':
        raise root.fail("Expected 'launch' as root tag",
                        fix='wrap the file in <launch> ... </launch> (YAML: launch: [...])')
    root.attr('deprecated')
    # like launch's parse_description, other attributes of the root are ignored
    actions = [parse_entity(child) for child in root.children()]
    description = DescriptionStep(actions)
    description.locate(root.file, root.line)
    return description


# ------------------------------------------------------------------------ load & plan


def load_description(path: Path) -> DescriptionStep:
    """Parse one launch file (by extension: .py, .xml, .yaml/.yml) into actions."""
    name = path.name
    if name.endswith('.py'):
        from robot_lab.launch.frontend_python import load_python_launch_file

        return load_python_launch_file(path)
    if name.endswith(('.yaml', '.yml')):
        from robot_lab.launch.frontend_yaml import load_yaml_launch_file

        return load_yaml_launch_file(path)
    from robot_lab.launch.frontend_xml import load_xml_launch_file

    if name.endswith('.xml'):
        return load_xml_launch_file(path)
    try:  # like AnyLaunchDescriptionSource: try each frontend
        return load_xml_launch_file(path)
    except LaunchError:
        from robot_lab.launch.frontend_yaml import load_yaml_launch_file

        return load_yaml_launch_file(path)


def _declared(step: LaunchStep, conditional_ok: bool = True) -> list[DeclareArgumentStep]:
    """Declared arguments reachable without executing (as launch's get_launch_arguments)."""
    found: list[DeclareArgumentStep] = []

    def walk(node: LaunchStep, conditional: bool) -> None:
        conditional = conditional or node.condition is not None
        if isinstance(node, DeclareArgumentStep):
            if (conditional_ok or not conditional) and all(d.name != node.name for d in found):
                found.append(node)
            return
        if isinstance(node, IncludeStep | TimerStep):
            return
        for child in node.children():
            walk(child, conditional)

    walk(step, False)
    return found


def find_launch_file(source: str | Path, file: str | None = None) -> Path:
    """`ros2 launch <pkg> <file>` or `ros2 launch <path>`: the launch file to read."""
    if file is None:
        path = Path(source)
        if not path.is_file():
            raise LaunchError(
                f"launch file not found: '{source}'",
                fix='give a path to a launch file, or a package and a file name: '
                'robot-lab launch <package> <file>')
        return path.resolve()
    from robot_lab.pkg.index import package_share

    try:
        share = package_share(str(source))
    except RobotLabError as err:
        raise LaunchError(err.message, fix=err.fix) from None
    for direct in (share / 'launch' / file, share / file):
        if direct.is_file():
            return direct.resolve()
    matches: list[Path] = []
    launch_files: set[str] = set()
    for root, dirs, files in os.walk(share):
        # an editable kit's share is the checkout: skip .venv, .git, colcon's build/install/log
        dirs[:] = [d for d in dirs if not d.startswith('.') and d not in _NOT_SHARE]
        matches += [Path(root, name) for name in files if name == file]
        launch_files.update(n for n in files if '.launch.' in n or n.endswith('_launch.py'))
    if len(matches) == 1:
        return matches[0].resolve()
    if matches:
        raise LaunchError(
            f"Found multiple files named '{file}' in the share directory of package "
            f"'{source}': {', '.join(str(m) for m in sorted(matches))}",
            fix='give the path of the one you mean instead of package and file')
    launch_dir = share / 'launch'
    have = sorted(p.name for p in launch_dir.iterdir() if p.is_file()) if launch_dir.is_dir() \
        else sorted(launch_files)
    raise LaunchError(
        f"file '{file}' was not found in the share directory of package '{source}' "
        f"which is at '{share}'",
        fix='the package has: ' + (', '.join(have) if have else 'no launch files')
        + ' (after adding one, rebuild: launch files are installed by data_files)')


def _number_labels(actions: list[Action]) -> None:
    """`sensor_node-1`: launch numbers processes as they start (timers after the rest)."""
    order: list[ProcessSpec] = []
    timers: list[tuple[float, TimerAction]] = []

    def walk(items: list[Action], delay: float) -> None:
        for item in items:
            if isinstance(item, ProcessSpec) and delay == 0.0:
                order.append(item)
            elif isinstance(item, TimerAction):
                timers.append((delay + item.period, item))

    walk(actions, 0.0)
    index = 0
    while index < len(timers):  # nested timers fire later still
        timers.sort(key=lambda t: t[0])
        delay, timer = timers[index]
        index += 1
        for item in timer.actions:
            if isinstance(item, ProcessSpec):
                order.append(item)
            elif isinstance(item, TimerAction):
                timers.append((delay + item.period, item))
    for number, spec in enumerate(order, start=1):
        spec.label = f'{spec.label}-{number}'


def describe_launch(
    source: str | Path,
    file: str | None = None,
    args: Mapping[str, str] | None = None,
) -> LaunchPlan:
    """Resolve a launch file completely (nothing is started): `robot-lab launch --print`."""
    from robot_lab.env import ros_environment

    path = find_launch_file(source, file)
    context = LaunchContext(args or {}, ros_environment())
    description = load_description(path)
    context.files.append(path)
    context.run([description])
    _number_labels(context.sink)
    arguments: dict[str, LaunchArgument] = {}
    for argument in context.arguments:  # an included file may declare the same name again
        arguments.setdefault(argument.name, argument)
    return LaunchPlan(source=path, actions=context.sink, arguments=list(arguments.values()))


def launch_arguments(source: str | Path, file: str | None = None) -> list[LaunchArgument]:
    """Declared arguments with defaults and descriptions (`--show-args`); none required."""
    path = find_launch_file(source, file)
    description = load_description(path)
    context = LaunchContext({}, dict(os.environ))
    context.files.append(path)
    result = []
    for declared in _declared(description):
        try:
            result.append(declared.argument(context))
        except (SubstitutionFailure, RobotLabError, ValueError, OSError):
            result.append(declared.argument(None))
    return result


def parse_launch_arguments(items: Iterable[str]) -> dict[str, str]:
    """['name:=value', ...] -> dict, with ros2 launch's error for a malformed one."""
    result: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition(':=')
        if not sep or not name:
            raise LaunchError(
                f"malformed launch argument '{item}', expected format '<name>:=<value>'",
                fix='write each as <name>:=<value>, e.g. robot_name:=robot_alpha')
        result[name] = value
    return result
