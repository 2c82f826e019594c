"""`robot-lab interface show TYPE`: the definition text `ros2 interface show` prints."""

from __future__ import annotations

import argparse
import sys

HELP = 'Show information about ROS interfaces'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='interface_verb', metavar='VERB')
    show = sub.add_parser('show', help='Output the interface definition')
    comments = show.add_mutually_exclusive_group()
    comments.add_argument('--all-comments', action='store_true',
                          help='Show all comments, including for nested interface definitions')
    comments.add_argument('--no-comments', action='store_true',
                          help='Show no comments or whitespace')
    show.add_argument('type', help="Show an interface definition (e.g. "
                      "'example_interfaces/msg/String'). Passing '-' reads it from stdin.")


def main(args: argparse.Namespace) -> int:
    from robot_lab.graph.interfaces import interface_show

    if args.interface_verb != 'show':
        args._parser.print_help()
        return 0
    name = sys.stdin.readline().strip() if args.type == '-' else args.type
    print(interface_show(name, comments=not args.no_comments,
                         nested_comments=args.all_comments))
    return 0
