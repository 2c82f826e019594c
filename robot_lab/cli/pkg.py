"""`robot-lab pkg create|list|prefix|executables`: ros2pkg's verbs, printed as ros2 prints."""

from __future__ import annotations

import argparse
import getpass
import sys

from robot_lab.errors import PackageNotFoundError

HELP = 'Various package related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='pkg_verb', metavar='VERB')

    create = sub.add_parser('create', help='Create a new ROS 2 package')
    create.add_argument('package_name', help='The package name')
    create.add_argument('--package-format', '--package_format', type=int, default=3,
                        choices=[3], help='The package.xml format.')
    create.add_argument('--description', default='TODO: Package description',
                        help='The description given in the package.xml')
    create.add_argument('--license', default='TODO: License declaration',
                        help='The license attached to this package')
    create.add_argument('--destination-directory', default='.',
                        help='Directory where to create the package directory')
    create.add_argument('--build-type', default='ament_python',
                        choices=['cmake', 'ament_cmake', 'ament_python'],
                        help='The build type to process the package with (this kit: '
                        'ament_python by default; ament_cmake for interface packages)')
    create.add_argument('--dependencies', nargs='+', default=[], help='list of dependencies')
    create.add_argument('--maintainer-email',
                        help='email address of the maintainer of this package')
    create.add_argument('--maintainer-name', default=getpass.getuser(),
                        help='name of the maintainer of this package')
    create.add_argument('--node-name', help='name of the empty executable')
    create.add_argument('--with-launch', action='store_true',
                        help='also create launch/NAME.launch.xml and install launch/ '
                        '(robot_lab extra)')
    create.add_argument('--with-config', action='store_true',
                        help='also create config/params.yaml and install config/ '
                        '(robot_lab extra)')
    create.set_defaults(_pkg=_create)

    listing = sub.add_parser('list', help='Output a list of available packages')
    listing.set_defaults(_pkg=_list)

    prefix = sub.add_parser('prefix', help='Output the prefix path of a package')
    prefix.add_argument('package_name', help='The package name')
    prefix.add_argument('--share', action='store_true',
                        help='Show share directory for the package')
    prefix.set_defaults(_pkg=_prefix)

    exe = sub.add_parser('executables', help='Output a list of package specific executables')
    exe.add_argument('package_name', nargs='?', help='The package name')
    exe.add_argument('--full-path', action='store_true', default=False,
                     help='Show full path of each executable')
    exe.set_defaults(_pkg=_executables)
    parser.set_defaults(_pkg=None)


def _create(args: argparse.Namespace) -> int:
    from robot_lab.pkg.create import plan_package

    plan = plan_package(
        args.package_name, args.destination_directory, args.build_type, args.dependencies,
        args.node_name, args.maintainer_name, args.maintainer_email, args.license,
        args.description, args.with_launch, args.with_config,
    )
    for line in plan.summary_lines():
        print(line)
    plan.write(lambda step: print(step.message) if step.message else None)
    if plan.warning:
        print(plan.warning)
    return 0


def _list(args: argparse.Namespace) -> int:
    from robot_lab.pkg.index import packages

    for name in sorted(packages()):
        print(name)
    return 0


def _prefix(args: argparse.Namespace) -> int:
    from robot_lab.pkg.index import package_prefix

    try:
        prefix = package_prefix(args.package_name)
    except PackageNotFoundError:
        print('Package not found', file=sys.stderr)
        return 1
    print(prefix / 'share' / args.package_name if args.share else prefix)
    return 0


def _executables(args: argparse.Namespace) -> int:
    from robot_lab.pkg.index import executables, package_prefix, packages

    names = sorted(packages()) if args.package_name is None else [args.package_name]
    for name in names:
        try:
            libdir = package_prefix(name) / 'lib' / name
            found = executables(name)
        except PackageNotFoundError:
            print(f"Package '{name}' not found", file=sys.stderr)
            return 1
        for exe in found:
            print(libdir / exe if args.full_path else f'{name} {exe}')
    return 0


def main(args: argparse.Namespace) -> int:
    if args._pkg is None:
        args._parser.print_help()
        return 0
    code: int = args._pkg(args)
    return code
