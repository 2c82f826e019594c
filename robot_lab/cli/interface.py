"""`robot-lab interface show|list|package|packages|proto`: what `ros2 interface …` prints."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from robot_lab.cli import run_sub_verb

if TYPE_CHECKING:
    from robot_lab.graph.interfaces import InterfaceKind

HELP = 'Show information about ROS interfaces'


def _only_flags(parser: argparse.ArgumentParser, what: str = 'Print out only the') -> None:
    parser.add_argument('-m', '--only-msgs', action='store_true', help=f'{what} message types')
    parser.add_argument('-s', '--only-srvs', action='store_true', help=f'{what} service types')
    parser.add_argument('-a', '--only-actions', action='store_true', help=f'{what} action types')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='interface_verb', metavar='VERB')
    lister = sub.add_parser('list', help='List all interface types available')
    _only_flags(lister)
    package = sub.add_parser('package',
                             help='Output a list of available interface types within one package')
    _only_flags(package)
    package.add_argument('package_name',
                         help="Name of the ROS package (e.g. 'example_interfaces')")
    packages = sub.add_parser('packages',
                              help='Output a list of packages that provide interfaces')
    packages.add_argument('-m', '--only-msgs', action='count',
                          help='Only list packages that generate messages')
    packages.add_argument('-s', '--only-srvs', action='count',
                          help='Only list packages that generate services')
    packages.add_argument('-a', '--only-actions', action='count',
                          help='Only list packages that generate actions')
    proto = sub.add_parser('proto', help='Output an interface prototype')
    proto.add_argument('type', help="Show an interface definition (e.g. "
                       "'example_interfaces/msg/String')")
    proto.add_argument('--no-quotes', action='store_true',
                       help='if true output has no outer quotes.')
    show = sub.add_parser('show', help='Output the interface definition')
    comments = show.add_mutually_exclusive_group()
    comments.add_argument('--all-comments', action='store_true',
                          help='Show all comments, including for nested interface definitions')
    comments.add_argument('--no-comments', action='store_true',
                          help='Show no comments or whitespace')
    show.add_argument('type', help="Show an interface definition (e.g. "
                      "'example_interfaces/msg/String'). Passing '-' reads it from stdin.")


def _kinds(args: argparse.Namespace) -> tuple[InterfaceKind, ...]:
    """The kinds the -m/-s/-a flags chose, in that order."""
    chosen: list[InterfaceKind] = []
    if args.only_msgs:
        chosen.append('msg')
    if args.only_srvs:
        chosen.append('srv')
    if args.only_actions:
        chosen.append('action')
    return tuple(chosen)


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.interface_verb, {
        'show': _show, 'list': _list, 'package': _package, 'packages': _packages, 'proto': _proto,
    })


def _show(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_show

    name = sys.stdin.readline().strip() if args.type == '-' else args.type
    print(interface_show(name, comments=not args.no_comments,
                         nested_comments=args.all_comments))
    return 0


def _list(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_list

    titles = {'msg': 'Messages:', 'srv': 'Services:', 'action': 'Actions:'}
    for kind in _kinds(args) or ('msg', 'srv', 'action'):
        print(titles[kind])
        for package, names in interface_list((kind,)).items():
            for name in names:
                print(f'    {package}/{name}')
    return 0


def _package(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_package

    for name in interface_package(args.package_name, _kinds(args) or ('msg', 'srv', 'action')):
        print(name)
    return 0


def _packages(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_packages

    kinds = _kinds(args)  # ros2cli: the first flag given wins
    for name in interface_packages(kinds[0] if kinds else None):
        print(name)
    return 0


def _proto(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_proto

    text = interface_proto(args.type)
    print(text if args.no_quotes else f'"{text}"')
    return 0
