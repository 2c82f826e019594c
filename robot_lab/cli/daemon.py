"""`robot-lab daemon start|stop|status`, and the `--no-daemon` the graph verbs share.

Prints what `ros2 daemon …` prints. `robot-lab launch` starts a daemon by itself; see
robot_lab/graph/daemon.py for what it is and why.
"""

from __future__ import annotations

import argparse
import atexit
from typing import Any

HELP = 'Various daemon related sub-commands'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='daemon_verb', metavar='VERB')
    start = sub.add_parser('start', help="Start the daemon if it isn't running")
    start.add_argument('--idle-timeout', type=float, default=None, metavar='SECONDS',
                       help='Exit after this long without a request (default: 7200)')
    start.add_argument('--owner', type=int, default=None, metavar='PID',
                       help='Exit when this process ends (./kit start passes JupyterLab)')
    sub.add_parser('stop', help='Stop the daemon if it is running')
    sub.add_parser('status', help='Output the status of the daemon')


def add_no_daemon(parser: argparse.ArgumentParser) -> None:
    """The `--no-daemon` option of ros2cli's graph verbs."""
    parser.add_argument('--no-daemon', action='store_true',
                        help='Do not spawn nor use an already running daemon')


def ask_daemon(args: argparse.Namespace, op: str, *, timeout: float | None = None,
               **params: Any) -> Any | None:
    """The daemon's answer for a graph verb, or None: then the verb asks the graph itself
    and, as ros2cli does, starts a daemon for the next command. It does so as it exits:
    the answer is not slowed, and a launch started a moment before (which binds the
    graph's socket first thing) keeps the daemon of its own."""
    if getattr(args, 'no_daemon', False):
        return None
    from robot_lab.graph.daemon import QUERY_TIMEOUT, query, start_for_later

    answer = query(op, timeout=QUERY_TIMEOUT if timeout is None else timeout, **params)
    if answer is None:
        atexit.register(start_for_later)
    return answer


def main(args: argparse.Namespace) -> int:
    from robot_lab.graph import daemon

    if args.daemon_verb == 'status':
        print('The daemon is running' if daemon.is_running() else 'The daemon is not running')
    elif args.daemon_verb == 'start':
        if daemon.is_running():
            print('The daemon is already running')
            return 0
        timeout = daemon.IDLE_TIMEOUT if args.idle_timeout is None else args.idle_timeout
        proc = daemon.start(detached=True, idle_timeout=timeout, owner=args.owner)
        if not daemon.wait_until_running(proc=proc):
            print('The daemon could not be started')
            return 1
        print('The daemon has been started')
    elif args.daemon_verb == 'stop':
        print('The daemon has been stopped' if daemon.stop() else 'The daemon is not running')
    else:
        args._parser.print_help()
    return 0
