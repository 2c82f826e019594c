"""`robot-lab run <pkg> <exec> [args] [--ros-args …]`: the `ros2 run` equivalent."""

from __future__ import annotations

import argparse
import os
import shlex

from robot_lab.env import ros_environment
from robot_lab.pkg.index import find_executable

HELP = 'Run a package specific executable'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '--prefix', metavar='PREFIX',
        help="Prefix command, which should go before the executable (e.g. 'gdb -ex run --args')",
    )
    parser.add_argument('package_name', help='Name of the ROS package')
    parser.add_argument('executable_name', help='Name of the executable')
    parser.add_argument(
        'argv', nargs=argparse.REMAINDER, help='Pass arbitrary arguments to the executable'
    )


def main(args: argparse.Namespace) -> int:
    path = find_executable(args.package_name, args.executable_name)
    cmd = [*(shlex.split(args.prefix) if args.prefix else []), str(path), *args.argv]
    env = ros_environment()
    # Become the node (same pid): Ctrl-C and kill reach it directly, nothing is left behind.
    os.execvpe(cmd[0], cmd, env)
    return 0  # pragma: no cover - execvpe does not return
