"""Launch substitutions: `$(var x)`, `$(find-pkg-share p)`, ... parsed and evaluated.

The grammar is launch's (ros2/launch frontend/grammar.lark): text with `$(name arg ...)`
parts, arguments separated by spaces, quoted with '..' or "..", substitutions nested, `\\x`
escapes x. The same classes serve XML, YAML and the Python API (compat/), so
`LaunchConfiguration('x')` and `$(var x)` are one object.
"""

from __future__ import annotations

import importlib
import math
import os
import random
import shlex
import shutil
import socket
import subprocess
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any, Protocol, TypeAlias

import yaml

__all__ = [
    'SomeSubstitution',
    'SomeSubstitutions',
    'Subs',
    'Substitution',
    'SubstitutionContext',
    'SubstitutionError',
    'SubstitutionFailure',
    'Text',
    'coerce',
    'condition_value',
    'perform',
]


class SubstitutionError(Exception):
    """A substitution that cannot be evaluated; the caller adds file and line."""


SubstitutionFailure = SubstitutionError  # launch's name for it


class SubstitutionContext(Protocol):
    """What a substitution may read: launch configurations, environment, current file."""

    configurations: dict[str, str]
    environment: dict[str, str]

    @property
    def current_file(self) -> Path | None: ...


class Substitution:
    """One part of a value, evaluated to text against a context."""

    def perform(self, context: SubstitutionContext) -> str:
        raise NotImplementedError

    def describe(self) -> str:
        """What --print shows: the class and its arguments, nothing performed."""
        args = []
        for value in vars(self).values():
            if isinstance(value, list) and all(isinstance(v, Substitution) for v in value):
                args.append(' + '.join(v.describe() for v in value) or "''")
        return f'{type(self).__name__}({", ".join(args)})'


Subs = list[Substitution]
# What launch's Python API accepts where it wants text (its SomeSubstitutionsType).
SomeSubstitution: TypeAlias = str | os.PathLike[str] | Substitution
SomeSubstitutions: TypeAlias = SomeSubstitution | Iterable[SomeSubstitution]


def perform(subs: Sequence[Substitution] | str, context: SubstitutionContext) -> str:
    """The text a list of substitutions evaluates to."""
    if isinstance(subs, str):
        return subs
    return ''.join(sub.perform(context) for sub in subs)


class Text(Substitution):
    """Literal text."""

    def __init__(self, text: str) -> None:
        self.text = text

    def perform(self, context: SubstitutionContext) -> str:
        return self.text

    def perform_text(self) -> str:
        return self.text

    def describe(self) -> str:
        return repr(self.text)


class LaunchConfiguration(Substitution):
    """`$(var name [default])`: a launch argument or `let` value."""

    def __init__(self, name: Subs, default: Subs | None = None) -> None:
        self.name, self.default = name, default

    def perform(self, context: SubstitutionContext) -> str:
        name = perform(self.name, context)
        if name in context.configurations:
            return context.configurations[name]
        if self.default is not None:
            return perform(self.default, context)
        raise SubstitutionFailure(f"launch configuration '{name}' does not exist")


class EnvironmentVariable(Substitution):
    """`$(env NAME [default])` (ROS 2 has no `optenv`: give a default instead)."""

    def __init__(self, name: Subs, default: Subs | None = None) -> None:
        self.name, self.default = name, default

    def perform(self, context: SubstitutionContext) -> str:
        name = perform(self.name, context)
        value = context.environment.get(name)
        if value is None and self.default is not None:
            value = perform(self.default, context)
        if value is None:
            raise SubstitutionFailure(f"environment variable '{name}' does not exist")
        return value


class PythonExpression(Substitution):
    """`$(eval 'expr' [modules])`: math names usable unqualified, as in launch."""

    def __init__(self, expression: Subs, modules: Subs | None = None) -> None:
        self.expression, self.modules = expression, modules

    def perform(self, context: SubstitutionContext) -> str:
        names = ['math']
        if self.modules is not None:
            names = [n.strip() for n in perform(self.modules, context).split(',') if n.strip()]
        scope: dict[str, object] = {}
        for name in names:
            module = importlib.import_module(name)
            if module is math:
                scope.update(vars(math))
            scope[name] = module
        expression = perform(self.expression, context)
        try:
            return str(eval(expression, {}, scope))
        except Exception as err:
            raise SubstitutionFailure(
                f'$(eval) of {expression!r} failed: {type(err).__name__}: {err}') from None


class Command(Substitution):
    """`$(command 'cmd' [on_stderr])`: the command's stdout."""

    def __init__(self, command: Subs, on_stderr: Subs | None = None) -> None:
        self.command, self.on_stderr = command, on_stderr

    def perform(self, context: SubstitutionContext) -> str:
        command = perform(self.command, context)
        on_stderr = perform(self.on_stderr, context) if self.on_stderr else 'fail'
        if on_stderr not in ('fail', 'ignore', 'warn', 'capture'):
            raise SubstitutionFailure(
                "expected 'on_stderr' to be one of: 'fail', 'ignore', 'warn' or 'capture'")
        try:
            result = subprocess.run(
                shlex.split(command), stdout=subprocess.PIPE, text=True,
                stderr=subprocess.STDOUT if on_stderr == 'capture' else subprocess.PIPE,
                env=context.environment, check=False,
            )
        except FileNotFoundError as err:
            raise SubstitutionFailure(f'file not found: {err}') from None
        if result.returncode != 0:
            message = f'executed command failed. Command: {command}'
            if result.stderr:
                message += f' Captured stderr output: {result.stderr.strip()}'
            raise SubstitutionFailure(message)
        if result.stderr and on_stderr == 'fail':
            raise SubstitutionFailure(
                f'executed command showed stderr output. Command: {command} '
                f'Captured stderr output: {result.stderr.strip()}')
        return result.stdout


class AnonName(Substitution):
    """`$(anon name)`: one unique name per id within a launch."""

    def __init__(self, name: Subs) -> None:
        self.name = name

    def perform(self, context: SubstitutionContext) -> str:
        name = perform(self.name, context)
        key = 'anon' + name
        if key not in context.configurations:
            unique = f'{name}_{socket.gethostname()}_{os.getpid()}_{random.randint(0, sys.maxsize)}'
            for char in '.-:':
                unique = unique.replace(char, '_')
            context.configurations[key] = unique
        return context.configurations[key]


class ThisLaunchFileDir(Substitution):
    """`$(dirname)`: the directory of the launch file being read."""

    def perform(self, context: SubstitutionContext) -> str:
        if context.current_file is None:
            raise SubstitutionFailure('ThisLaunchFileDir used outside of a launch file')
        return str(context.current_file.parent)


class ThisLaunchFile(Substitution):
    """`$(filename)`: the launch file being read."""

    def perform(self, context: SubstitutionContext) -> str:
        if context.current_file is None:
            raise SubstitutionFailure('ThisLaunchFile used outside of a launch file')
        return str(context.current_file)


class FindExecutable(Substitution):
    """`$(find-exec name)`: an executable on PATH."""

    def __init__(self, name: Subs) -> None:
        self.name = name

    def perform(self, context: SubstitutionContext) -> str:
        name = perform(self.name, context)
        found = shutil.which(name, path=context.environment.get('PATH'))
        if found is None:
            raise SubstitutionFailure(f"executable '{name}' not found on the PATH")
        return found


class FindPackagePrefix(Substitution):
    """`$(find-pkg-prefix pkg)`, through robot_lab's ament index."""

    def __init__(self, package: Subs) -> None:
        self.package = package

    def perform(self, context: SubstitutionContext) -> str:
        from robot_lab.pkg.index import package_prefix

        return str(package_prefix(perform(self.package, context), context.environment))


class FindPackageShare(FindPackagePrefix):
    """`$(find-pkg-share pkg)`."""

    def perform(self, context: SubstitutionContext) -> str:
        from robot_lab.pkg.index import package_share

        return str(package_share(perform(self.package, context), context.environment))


class ExecutableInPackage(Substitution):
    """`$(exec-in-pkg exec pkg)`: <prefix>/lib/<pkg>/<exec>."""

    def __init__(self, executable: Subs, package: Subs) -> None:
        self.executable, self.package = executable, package

    def perform(self, context: SubstitutionContext) -> str:
        from robot_lab.pkg.index import find_executable

        package = perform(self.package, context)
        return str(find_executable(package, perform(self.executable, context), context.environment))


class FileContent(Substitution):
    """`$(file-content path)`."""

    def __init__(self, path: Subs) -> None:
        self.path = path

    def perform(self, context: SubstitutionContext) -> str:
        path = perform(self.path, context)
        try:
            return Path(path).read_text()
        except FileNotFoundError:
            raise SubstitutionFailure(f'File not found: {path}') from None


class LaunchLogDir(Substitution):
    """`$(log_dir)`: this launch's log directory (made when first asked for)."""

    def perform(self, context: SubstitutionContext) -> str:
        log_dir = getattr(context, 'log_dir', None)
        if log_dir is None:
            raise SubstitutionFailure('LaunchLogDir used outside of a launch')
        return str(log_dir())


class LocalSubstitution(Substitution):
    """LocalSubstitution('event.reason'): a value of the context's locals (in an event
    handler: the event being handled)."""

    def __init__(self, expression: str, description: str | None = None) -> None:
        self.expression, self.description = expression, description

    def perform(self, context: SubstitutionContext) -> str:
        value: object = getattr(context, 'locals', None)
        for part in self.expression.split('.'):
            if not hasattr(value, part):
                raise SubstitutionFailure(
                    f"LocalSubstitution('{self.expression}'): '{part}' is not in the "
                    "context's locals (event.* exists only inside an event handler)")
            value = getattr(value, part)
        return str(value)

    def describe(self) -> str:
        return self.description or f"LocalVar('{self.expression}')"


class PathJoin(Substitution):
    """PathJoinSubstitution (Python API only)."""

    def __init__(self, parts: list[Subs]) -> None:
        self.parts = parts

    def perform(self, context: SubstitutionContext) -> str:
        return os.path.join(*(perform(part, context) for part in self.parts))

    def describe(self) -> str:
        parts = (' + '.join(sub.describe() for sub in part) for part in self.parts)
        return f'PathJoinSubstitution([{", ".join(parts)}])'


_LIST_TYPES = {'list_of_str': str, 'list_of_bool': bool, 'list_of_float': float,
               'list_of_int': int}
TYPE_NAMES = ('str', 'bool', 'float', 'int', *_LIST_TYPES, 'yaml')


def _yaml_value(text: str) -> Any:
    if not text:
        return text
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise ValueError(f"Failed to convert '{text}' using yaml rules: {err}") from None
    return value


def coerce(text: str, type_name: str | None = None) -> Any:
    """launch's coerce_to_type: `type_name` None or 'yaml' -> YAML rules, else that type."""
    if type_name in (None, 'yaml'):
        value = _yaml_value(text)
        if not isinstance(value, str | int | float | bool | list):
            raise ValueError(f"Failed to convert '{text}' using yaml rules: "
                             f'output type is not allowed, got {type(value)}')
        return value
    if type_name == 'str':
        return text
    if type_name in ('int', 'float'):
        kind: type = int if type_name == 'int' else float
        try:
            return kind(text)
        except ValueError:
            raise ValueError(f"Cannot convert value '{text}' to '{type_name}'") from None
    if type_name == 'bool':
        value = _yaml_value({'1': 'true', '0': 'false'}.get(text, text))
        if not isinstance(value, bool):
            raise ValueError(f"Cannot convert value '{text}' to 'bool'")
        return value
    if type_name in _LIST_TYPES:
        item = _LIST_TYPES[type_name]
        value = _yaml_value(text)
        ok = isinstance(value, list) and all(
            isinstance(x, item) and not (item is not bool and isinstance(x, bool))
            for x in value
        )
        if item is float and isinstance(value, list):
            ok = all(isinstance(x, int | float) and not isinstance(x, bool) for x in value)
            value = [float(x) for x in value] if ok else value
        if not ok:
            raise ValueError(f"Cannot convert value '{text}' to a list of '{item.__name__}'")
        return value
    raise ValueError(f"Got invalid type identifier '{type_name}'")


def condition_value(text: str) -> bool:
    """`if=`/`unless=` and IfCondition: 'true'/'1' or 'false'/'0' after strip and lower."""
    value = text.strip().lower()
    if value in ('true', '1'):
        return True
    if value in ('false', '0'):
        return False
    raise SubstitutionFailure(
        f'Unexpected condition expression: {text!r}; expected one of: '
        "['true', '1', 'false', '0']")
