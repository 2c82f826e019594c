"""`robot-lab lifecycle nodes|get|list|set`: prints what `ros2 lifecycle …` (Jazzy) prints."""

from __future__ import annotations

import argparse
import sys

from robot_lab.cli import run_sub_verb

HELP = 'Various lifecycle related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='lifecycle_verb', metavar='VERB')
    nodes = sub.add_parser('nodes', help='Output a list of nodes with lifecycle')
    nodes.add_argument('-a', '--all', action='store_true',
                       help='Display all nodes even hidden ones')
    nodes.add_argument('-c', '--count-nodes', action='store_true',
                       help='Only display the number of nodes discovered')

    get = sub.add_parser('get', help='Get lifecycle state for one or more nodes')
    get.add_argument('node_name', nargs='?', help='Name of the ROS node. If no name is '
                     'provided, then get the state for all nodes.')
    get.add_argument('--include-hidden-nodes', '-a', '--all', action='store_true',
                     help='Consider hidden nodes as well')
    get.add_argument('--timeout', metavar='N', type=float, default=10.0,
                     help='Maximum time to wait for response in seconds')

    listing = sub.add_parser('list', help='Output a list of available transitions')
    listing.add_argument('node_name', help='Name of the ROS node')
    listing.add_argument('-a', '--all', action='store_true',
                         help='Display all existing transitions')

    setter = sub.add_parser('set', help='Trigger lifecycle state transition')
    setter.add_argument('node_name', help='Name of the ROS node')
    setter.add_argument('transition', help='The lifecycle transition')


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.lifecycle_verb, {
        'nodes': _nodes, 'get': _get, 'list': _list, 'set': _set,
    })


def _nodes(args: argparse.Namespace) -> int:
    from robot_lab.graph.lifecycle import lifecycle_nodes

    found = lifecycle_nodes(include_hidden=args.all)
    if args.count_nodes:
        print(len(found))
    elif found:
        print(*found, sep='\n')
    return 0


def _get(args: argparse.Namespace) -> int:
    from robot_lab.graph.discovery import absolute_name
    from robot_lab.graph.lifecycle import lifecycle_nodes, lifecycle_state

    found = lifecycle_nodes(include_hidden=args.include_hidden_nodes)
    if args.node_name:
        if absolute_name(args.node_name) not in found:
            print('Node not found', file=sys.stderr)
            return 1
        found = [absolute_name(args.node_name)]
    for node in found:
        label, state_id = lifecycle_state(node, timeout=args.timeout)
        print(('' if args.node_name else f'{node}: ') + f'{label} [{state_id}]')
    return 0


def _list(args: argparse.Namespace) -> int:
    from robot_lab.graph.lifecycle import lifecycle_transitions

    for t in lifecycle_transitions(args.node_name, every=args.all):
        print(f'- {t.label} [{t.id}]\n\tStart: {t.start}\n\tGoal: {t.goal}')
    return 0


def _set(args: argparse.Namespace) -> int:
    from robot_lab.graph.lifecycle import lifecycle_change_state

    if lifecycle_change_state(args.node_name, args.transition):
        print('Transitioning successful')
        return 0
    print('Transitioning failed', file=sys.stderr)
    return 1
