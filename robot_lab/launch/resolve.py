"""Launch files -> one LaunchPlan, with launch/launch_ros semantics and nothing started.

Finds the file (`<pkg> <file>` or a path), has its frontend parse it into actions
(frontend_xml, frontend_yaml, frontend_python), and executes them against a
LaunchContext, which resolves every process into a ProcessSpec. Every problem is a
LaunchError (or ParamFileError) with the file and line.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from robot_lab.errors import LaunchError, RobotLabError
from robot_lab.launch.action import LaunchDescriptionStep, LaunchStep
from robot_lab.launch.actions.include import IncludeStep, declared_arguments
from robot_lab.launch.context import LaunchContext
from robot_lab.launch.plan import (
    Action,
    LaunchArgument,
    LaunchPlan,
    ProcessSpec,
    TimerSpec,
)
from robot_lab.launch.substitutions import SubstitutionFailure, perform

__all__ = [
    'describe_launch',
    'find_launch_file',
    'included_launch_file',
    'launch_arguments',
    'load_launch_file',
    'parse_launch_arguments',
]

_NOT_SHARE = {'build', 'install', 'log', '__pycache__', 'node_modules'}


def load_launch_file(path: Path) -> LaunchDescriptionStep:
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
    timers: list[tuple[float, TimerSpec]] = []

    def walk(items: list[Action], delay: float) -> None:
        for item in items:
            if isinstance(item, ProcessSpec) and delay == 0.0:
                order.append(item)
            elif isinstance(item, TimerSpec):
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
            elif isinstance(item, TimerSpec):
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
    context.load_launch_file = load_launch_file
    description = load_launch_file(path)
    context.files.append(path)
    context.run([description])
    _number_labels(context.sink)
    arguments: dict[str, LaunchArgument] = {}
    for argument in context.arguments:  # an included file may declare the same name again
        arguments.setdefault(argument.name, argument)
    return LaunchPlan(source=path, actions=context.sink, arguments=list(arguments.values()),
                      log_dir=context.made_log_dir)


def launch_arguments(source: str | Path, file: str | None = None) -> list[LaunchArgument]:
    """Declared arguments with defaults and descriptions (`--show-args`); none required."""
    path = find_launch_file(source, file)
    description = load_launch_file(path)
    context = LaunchContext({}, dict(os.environ))
    context.load_launch_file = load_launch_file
    context.files.append(path)
    result = []
    for declared in declared_arguments(description):
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


def included_launch_file(step: LaunchStep) -> tuple[Path, LaunchDescriptionStep] | None:
    """An include's file and description when its path needs no launch context (a literal
    path, `os.path.join(get_package_share_directory(...), ...)`, `$(find-pkg-share ...)`):
    what `--print` expands, as launch's `try_get_launch_description_without_context` does.
    A path that needs an argument or the including file stays unexpanded (None)."""
    if not isinstance(step, IncludeStep):
        return None
    context = LaunchContext({}, dict(os.environ))
    try:
        path = Path(os.path.abspath(perform(step.path, context)))
        if not path.is_file():
            return None
        return path, load_launch_file(path)
    except (SubstitutionFailure, RobotLabError, OSError, ValueError):
        return None
