"""`robot-lab node list|info`: prints what `ros2 node list|info` (Jazzy) prints."""

from __future__ import annotations

import argparse
import sys

from robot_lab.cli.daemon import add_no_daemon, ask_daemon

HELP = 'Various node related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='node_verb', metavar='VERB')
    lister = sub.add_parser('list', help='Output a list of available nodes')
    lister.add_argument('-a', '--all', action='store_true',
                        help='Display all nodes even hidden ones')
    lister.add_argument('-c', '--count-nodes', action='store_true',
                        help='Only display the number of nodes discovered')
    add_no_daemon(lister)
    info = sub.add_parser('info', help='Output information about a node')
    info.add_argument('node_name', help='Node name to request information')
    info.add_argument('--include-hidden', action='store_true',
                      help='Display hidden topics, services, and actions as well')


def _print_names_and_types(items: list[tuple[str, list[str]]]) -> None:
    # ros2cli prints one (possibly empty) line per section even when it has no entries.
    print(*[f'    {name}: {", ".join(types)}' for name, types in items], sep='\n')


def main(args: argparse.Namespace) -> int:
    from robot_lab.graph import api

    if args.node_verb == 'list':
        names = ask_daemon(args, 'node_list', include_hidden=args.all)
        if names is None:
            names = api.node_list(include_hidden=args.all)
        if args.count_nodes:
            print(len(names))
        elif names:
            if len(set(names)) < len(names):
                print('WARNING: Be aware that there are nodes in the graph that share an exact '
                      'name, which can have unintended side effects.', file=sys.stderr)
            print(*names, sep='\n')
        return 0
    if args.node_verb == 'info':
        answer = ask_daemon(args, 'node_info', name=args.node_name,
                            include_hidden=args.include_hidden)
        if answer is not None:
            sections = {key: [(name, list(types)) for name, types in value]
                        for key, value in answer.items() if key != 'name'}
            info = api.NodeInfo(str(answer['name']), **sections)
        else:
            info = api.node_info(args.node_name, include_hidden=args.include_hidden)
        print(info.name)
        for title, items in (
            ('Subscribers', info.subscribers), ('Publishers', info.publishers),
            ('Service Servers', info.service_servers), ('Service Clients', info.service_clients),
            ('Action Servers', info.action_servers), ('Action Clients', info.action_clients),
        ):
            print(f'  {title}:')
            _print_names_and_types(items)
        return 0
    args._parser.print_help()
    return 0
