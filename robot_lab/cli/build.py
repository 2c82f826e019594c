"""`robot-lab build [WORKSPACE]`: the real `colcon build`, with progress and the errors
that matter."""

from __future__ import annotations

import argparse
import sys

HELP = 'Build the packages of a workspace with colcon (colcon build)'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('workspace', nargs='?', default='.',
                        help='The workspace folder (holding src/); default: the current one')
    parser.add_argument('--packages-select', nargs='+', metavar='PKG_NAME',
                        help='Only process a subset of packages')
    parser.add_argument('--symlink-install', action='store_true',
                        help='Use symlinks instead of copying files where possible')
    parser.add_argument('--kit', action='store_true',
                        help="Build the kit's own ament packages (example_interfaces, "
                        'action_tutorials_interfaces, turtlesim, ament_lint_auto/common) '
                        'into its venv; ./kit setup runs this')
    parser.add_argument('--force', action='store_true',
                        help='With --kit: rebuild even the packages that are up to date')
    parser.add_argument('--cpp', action='store_true',
                        help='With --kit: also build their C++ type supports (for a C++ '
                        'interface package that depends on one; rclpy needs only the C ones)')


def _kit(force: bool, cpp: bool) -> int:
    from robot_lab.pkg.kit_packages import build_kit_packages

    result = build_kit_packages(force=force, cpp=cpp,
                                progress=lambda line: print(line, flush=True))
    for line in result.lines():
        print(line)
    return 0


def main(args: argparse.Namespace) -> int:
    from robot_lab.pkg.build import build

    if args.kit:
        return _kit(args.force, args.cpp)

    result = build(args.workspace, packages_select=args.packages_select,
                   symlink_install=args.symlink_install, progress=True)
    print(str(result), file=sys.stdout if result.ok else sys.stderr)
    if result.ok:
        print('To use it: source install/setup.bash (shell) or '
              "robot_lab.use_workspace('" + str(result.workspace) + "') (notebook)")
    return 0 if result.ok else 1
