"""`robot-lab action list|type|info|send_goal`: prints what `ros2 action …` (Jazzy) prints."""

from __future__ import annotations

import argparse
import queue
import sys
from typing import Any

from robot_lab.cli import print_names, run_sub_verb
from robot_lab.cli.daemon import ask_daemon

HELP = 'Various action related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='action_verb', metavar='VERB')
    lister = sub.add_parser('list', help='Output a list of action names')
    lister.add_argument('-t', '--show-types', action='store_true',
                        help='Additionally show the action type')
    lister.add_argument('-c', '--count-actions', action='store_true',
                        help='Only display the number of actions discovered')

    info = sub.add_parser('info', help='Print information about an action')
    info.add_argument('action_name',
                      help="Name of the ROS action to get info (e.g. '/fibonacci')")
    info.add_argument('-t', '--show-types', action='store_true',
                      help='Additionally show the action type')
    info.add_argument('-c', '--count', action='store_true',
                      help='Only display the number of action clients and action servers')

    kind = sub.add_parser('type', help="Print a action's type")
    kind.add_argument('action_name',
                      help="Name of the ROS action to get info (e.g. '/fibonacci')")

    goal = sub.add_parser('send_goal', help='Send an action goal')
    goal.add_argument('action_name', help="Name of the ROS action (e.g. '/fibonacci')")
    goal.add_argument('action_type', help="Type of the ROS action "
                      "(e.g. 'example_interfaces/action/Fibonacci')")
    values = goal.add_mutually_exclusive_group()
    values.add_argument('goal', nargs='?', default='{}',
                        help="Goal request values in YAML format (e.g. '{order: 10}')")
    values.add_argument('--stdin', action='store_true', help='Read goal from standard input')
    goal.add_argument('-f', '--feedback', action='store_true',
                      help='Echo feedback messages for the goal')


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.action_verb, {
        'list': _list, 'info': _info, 'type': _type, 'send_goal': _send_goal,
    })


def _list(args: argparse.Namespace) -> int:
    # From the daemon, as ros2cli does: a fresh participant on a loaded host can answer
    # before it has heard the action servers.
    found = ask_daemon(args, 'action_list')
    if found is None:
        from robot_lab.graph.actions import action_list

        found = action_list()
    print_names([(name, list(types)) for name, types in found], count=args.count_actions,
                show_types=args.show_types)
    return 0


def _info(args: argparse.Namespace) -> int:
    from robot_lab.graph.actions import ActionInfo, action_info

    answer = ask_daemon(args, 'action_info', name=args.action_name)
    if answer is not None:
        info = ActionInfo(name=answer['name'],
                          clients=[(node, list(types)) for node, types in answer['clients']],
                          servers=[(node, list(types)) for node, types in answer['servers']])
    else:
        info = action_info(args.action_name)
    print(f'Action: {args.action_name}')
    for title, entries in (('Action clients', info.clients), ('Action servers', info.servers)):
        print(f'{title}: {len(entries)}')
        if args.count:
            continue
        for node, types in entries:
            print(f'    {node} [{", ".join(types)}]' if args.show_types else f'    {node}')
    return 0


def _type(args: argparse.Namespace) -> int:
    from robot_lab.graph.actions import action_type

    types = action_type(args.action_name)
    for name in types:
        print(name)
    return 0 if types else 1  # ros2cli prints nothing and exits 1 for an unknown action


def _send_goal(args: argparse.Namespace) -> int:
    from robot_lab.graph.actions import action_class, action_client, send_goal
    from robot_lab.graph.discovery import wait_until
    from robot_lab.messages import message_from_yaml, message_to_yaml

    values = sys.stdin.read() if args.stdin else args.goal
    cls = action_class(args.action_type)  # The passed action type is invalid
    goal = message_from_yaml(cls.Goal, values)  # Failed to populate ...
    client = action_client(args.action_name, args.action_type)
    print('Waiting for an action server to become available...', flush=True)
    wait_until(lambda: True if client.server_is_ready() else None, 1e9)
    print(f'Sending goal:\n     {message_to_yaml(goal)}', flush=True)
    # Feedback arrives on the session's thread; it is printed here, in order, after the
    # "Goal accepted" line (ros2cli's single thread gives the same order).
    inbox: queue.Queue[Any] = queue.Queue()
    sent = send_goal(args.action_name, args.action_type, goal, wait=False,
                     server_timeout=1e9, feedback=inbox.put if args.feedback else None)
    if not sent.accepted:
        print('Goal was rejected.')
        return 0
    print(f'Goal accepted with ID: {sent.goal_id}\n', flush=True)
    try:
        while not (sent.done and inbox.empty()):
            try:
                feedback = inbox.get(timeout=0.05)
            except queue.Empty:
                continue
            print(f'Feedback:\n    {message_to_yaml(feedback)}', flush=True)
    except KeyboardInterrupt:
        if not sent.done:
            print('Canceling goal...', flush=True)
            if sent.cancel():
                print('Goal canceled.')
        raise
    print(f'Result:\n    {message_to_yaml(sent.result)}')
    print(f'Goal finished with status: {sent.status}')
    return 0
