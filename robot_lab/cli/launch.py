"""`robot-lab launch <pkg> <file> [name:=value …]`: the `ros2 launch` equivalent.

Also `robot-lab launch <path> [name:=value …]`, `--show-args` and `--print` (the parsed
description, nothing evaluated). The whole launch file is resolved and its parameter files
checked before anything starts, so an error is one line and exit code 1 with no process
left behind.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from robot_lab.launch.fork_client import ForkServer, start_early
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.parameters import check_param_files
from robot_lab.launch.plan import (
    LaunchArgument,
    LaunchPlan,
)
from robot_lab.launch.runner import run_supervisor
from robot_lab.launch.supervisor import Supervisor

if TYPE_CHECKING:
    from robot_lab.graph.daemon import Listener
    from robot_lab.graph.expected import LaunchAnnouncement

HELP = 'Run a launch file'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '-n', '--noninteractive', default=not sys.stdin.isatty(), action='store_true',
        help='Run the launch system non-interactively, with no terminal associated')
    parser.add_argument(
        '-d', '--debug', default=False, action='store_true',
        help='Put the launch system in debug mode, provides more verbose output.')
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        '-p', '--print', '--print-description', dest='print', default=False,
        action='store_true',
        help='Print the launch description to the console without launching it.')
    group.add_argument(
        '-s', '--show-args', '--show-arguments', dest='show_args', default=False,
        action='store_true', help='Show arguments that may be given to the launch file.')
    parser.add_argument(
        '-a', '--show-all-subprocesses-output', dest='show_all', default=False,
        action='store_true',
        help="Show all launched subprocesses' output by overriding their output "
        "configuration (as output='both')")
    parser.add_argument(
        'package_name', help='Name of the ROS package which contains the launch file')
    parser.add_argument('launch_file_name', nargs='?', help='Name of the launch file')
    parser.add_argument(
        'launch_arguments', nargs='*',
        help="Arguments to the launch file; '<name>:=<value>' (for duplicates, last one wins)")


def _source(args: argparse.Namespace) -> tuple[str, str | None, list[str]]:
    """(package or path, file or None, launch arguments), decided as ros2 launch does."""
    argv = list(args.launch_arguments)
    if os.path.isfile(args.package_name):
        # Single-file mode: the second positional is already a launch argument.
        if args.launch_file_name is not None:
            argv.insert(0, args.launch_file_name)
        return args.package_name, None, argv
    return args.package_name, args.launch_file_name, argv


def format_arguments(arguments: list[LaunchArgument]) -> str:
    """`ros2 launch --show-args` output."""
    lines = ["Arguments (pass arguments as '<name>:=<value>'):"]
    for arg in arguments:
        lines.append('')
        lines.append(f"    '{arg.name}':")
        lines.append(f'        {arg.description or "no description given"}')
        if arg.choices:
            lines.append(f'        Valid choices are: {arg.choices}')
        if arg.default is not None:
            lines.append(f"        (default: '{arg.default}')")
    if not arguments:
        lines.append('')
        lines.append('  No arguments.')
    return '\n'.join(lines)


def main(args: argparse.Namespace) -> int:
    from robot_lab.launch.resolve import (
        describe_launch,
        launch_arguments,
        parse_launch_arguments,
    )

    source, file, argv = _source(args)
    if args.show_args:
        print(format_arguments(launch_arguments(source, file)))
        return 0
    if args.print:
        # like ros2 launch --print: the parsed description, nothing evaluated or written
        from robot_lab.launch.introspect import format_description
        from robot_lab.launch.resolve import (
            find_launch_file,
            included_launch_file,
            load_launch_file,
        )

        parse_launch_arguments(argv)  # a malformed one is still an error
        path = find_launch_file(source, file)
        print(format_description(load_launch_file(path), path, included_launch_file))
        return 0
    # First thing, before the launch file is read: the graph daemon's socket, and word that
    # a launch is starting, so a `node list` typed from now on waits for its nodes and a
    # warm answer (see robot_lab/graph/daemon.py and expected.py).
    from robot_lab.graph.expected import LaunchAnnouncement, graph_dir

    listener = _graph_listener()
    announcement = LaunchAnnouncement(graph_dir())
    announcement.starting()
    forks = start_early(source) if file is not None else None
    try:
        plan = describe_launch(source, file, parse_launch_arguments(argv))
        if args.show_all:
            for spec in plan.processes():
                spec.output = 'both'
        return run(plan, noninteractive=args.noninteractive, debug=args.debug,
                   graph_listener=listener, announcement=announcement, fork_server=forks)
    finally:
        announcement.close()
        if listener is not None:
            listener.close()  # a no-op once handed to the daemon
        if forks is not None:
            forks.discard()  # unused if the file failed to load; else closed already


def _graph_listener() -> Listener | None:
    from robot_lab.graph import daemon

    if daemon.disabled() or daemon.is_running():
        return None
    return daemon.Listener.bind()


def run(plan: LaunchPlan, *, noninteractive: bool, debug: bool = False,
        on_start: Callable[[Supervisor], None] | None = None,
        graph_listener: Listener | None = None,
        announcement: LaunchAnnouncement | None = None,
        fork_server: ForkServer | None = None) -> int:
    """Run `plan` in this (main) thread, Ctrl-C and SIGTERM stopping it in order.

    A graph daemon runs beside the nodes, so `robot-lab node list` in another terminal
    answers from a warm graph at once (ROBOT_LAB_NO_DAEMON=1 does without).
    """
    from robot_lab.graph import daemon

    check_param_files(plan)
    output = LaunchOutput(sys.stdout, debug=debug, log_dir=plan.log_dir)
    supervisor = Supervisor(plan, output, noninteractive=noninteractive,
                            graph_daemon=not daemon.disabled(),
                            graph_listener=graph_listener, announcement=announcement,
                            fork_server=fork_server)
    return run_supervisor(supervisor, on_start=on_start)
