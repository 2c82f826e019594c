"""`robot-lab service list [-t]`: prints what `ros2 service list` prints."""

from __future__ import annotations

import argparse

from robot_lab.cli.daemon import add_no_daemon, ask_daemon

HELP = 'Various service related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='service_verb', metavar='VERB')
    lister = sub.add_parser('list', help='Output a list of available services')
    lister.add_argument('-t', '--show-types', action='store_true',
                        help='Additionally show the service type')
    lister.add_argument('-c', '--count-services', action='store_true',
                        help='Only display the number of services discovered')
    lister.add_argument('--include-hidden-services', action='store_true',
                        help='Consider hidden services as well')
    add_no_daemon(lister)


def main(args: argparse.Namespace) -> int:
    from robot_lab.graph.services import service_list_typed

    if args.service_verb != 'list':
        args._parser.print_help()
        return 0
    hidden = args.include_hidden_services
    found = ask_daemon(args, 'service_list', include_hidden=hidden)
    if found is None:
        found = service_list_typed(include_hidden=hidden)
    if args.count_services:
        print(len(found))
        return 0
    for name, types in found:
        print(f'{name} [{", ".join(types)}]' if args.show_types else name)
    return 0
