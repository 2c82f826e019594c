"""`robot-lab service list|type|find|info|call`: prints what `ros2 service …` (Jazzy) prints."""

from __future__ import annotations

import argparse
import sys
import time

from robot_lab.cli.daemon import add_no_daemon, ask_daemon

HELP = 'Various service related sub-commands'


def _hidden_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--include-hidden-services', action='store_true',
                        help='Consider hidden services as well')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='service_verb', metavar='VERB')
    lister = sub.add_parser('list', help='Output a list of available services')
    lister.add_argument('-t', '--show-types', action='store_true',
                        help='Additionally show the service type')
    lister.add_argument('-c', '--count-services', action='store_true',
                        help='Only display the number of services discovered')
    _hidden_flag(lister)
    add_no_daemon(lister)

    kind = sub.add_parser('type', help="Output a service's type")
    kind.add_argument('service_name', help="Name of the ROS service to get type "
                      "(e.g. '/talker/list_parameters')")
    _hidden_flag(kind)

    find = sub.add_parser('find', help='Output a list of available services of a given type')
    find.add_argument('service_type', help='Name of the ROS service type to filter for '
                      "(e.g. 'rcl_interfaces/srv/ListParameters')")
    find.add_argument('-c', '--count-services', action='store_true',
                      help='Only display the number of services discovered')
    _hidden_flag(find)
    add_no_daemon(find)

    info = sub.add_parser('info', help='Print information about a service')
    info.add_argument('service_name',
                      help="Name of the ROS service to get info (e.g. '/add_two_ints')")
    _hidden_flag(info)
    add_no_daemon(info)

    call = sub.add_parser('call', help='Call a service')
    call.add_argument('service_name',
                      help="Name of the ROS service to call to (e.g. '/add_two_ints')")
    call.add_argument('service_type',
                      help="Type of the ROS service (e.g. 'std_srvs/srv/Empty')")
    values = call.add_mutually_exclusive_group()
    values.add_argument('values', nargs='?', default='{}',
                        help="Values to fill the service request with in YAML format "
                        "(e.g. '{a: 1, b: 2}'), otherwise the service request will be "
                        'published with default values')
    values.add_argument('--stdin', action='store_true', help='Read values from standard input')
    call.add_argument('-r', '--rate', metavar='N', type=float,
                      help='Repeat the call at a specific rate in Hz')
    call.add_argument('-n', '--times', metavar='N', type=int, default=None,
                      help='with --rate: stop after N calls (robot_lab; ros2cli repeats until '
                      'Ctrl-C)')


def main(args: argparse.Namespace) -> int:
    verbs = {'list': _list, 'type': _type, 'find': _find, 'info': _info, 'call': _call}
    verb = verbs.get(args.service_verb or '')
    if verb is None:
        args._parser.print_help()
        return 0
    return verb(args)


def _typed(args: argparse.Namespace) -> list[tuple[str, list[str]]]:
    from robot_lab.graph.services import service_list_typed

    hidden = args.include_hidden_services
    found = ask_daemon(args, 'service_list', include_hidden=hidden)
    if found is None:
        found = service_list_typed(include_hidden=hidden)
    return [(name, list(types)) for name, types in found]


def _list(args: argparse.Namespace) -> int:
    found = _typed(args)
    if args.count_services:
        print(len(found))
        return 0
    for name, types in found:
        print(f'{name} [{", ".join(types)}]' if args.show_types else name)
    return 0


def _type(args: argparse.Namespace) -> int:
    from robot_lab.graph.nodes import is_hidden
    from robot_lab.graph.services import service_type

    if is_hidden(args.service_name) and not args.include_hidden_services:
        return 1
    types = service_type(args.service_name)
    for name in types:
        print(name)
    return 0 if types else 1  # ros2cli prints nothing and exits 1 for an unknown service


def _find(args: argparse.Namespace) -> int:
    found = [name for name, types in _typed(args) if args.service_type in types]
    if args.count_services:
        print(len(found))
    else:
        for name in found:
            print(name)
    return 0


def _info(args: argparse.Namespace) -> int:
    from robot_lab.graph.services import service_info

    info = service_info(args.service_name)  # GraphError: Unknown service '/x'
    print(f'Type: {info.types[0] if len(info.types) == 1 else info.types}')
    print(f'Clients count: {info.clients}')
    print(f'Services count: {info.servers}')
    return 0


def _call(args: argparse.Namespace) -> int:
    from robot_lab.errors import GraphError
    from robot_lab.graph.services import (
        send_request,
        service_class,
        service_client,
        wait_for_service,
    )
    from robot_lab.messages import message_from_yaml

    if args.rate is not None and args.rate <= 0:
        raise GraphError('rate must be greater than zero', fix='e.g. `-r 1` for once a second')
    period = 1.0 / args.rate if args.rate else None
    values = sys.stdin.read() if args.stdin else args.values
    cls = service_class(args.service_type)  # The passed service type is invalid
    request = message_from_yaml(cls.Request, values)  # Failed to populate field ...
    client = service_client(args.service_name, args.service_type)
    if not client.service_is_ready():
        print('waiting for service to become available...', flush=True)
        wait_for_service(client, None)
    calls = 0
    while True:
        print(f'requester: making request: {request!r}\n', flush=True)
        last_call = time.monotonic()
        response = send_request(client, request, None, args.service_name)
        print(f'response:\n{response!r}\n', flush=True)
        calls += 1
        if period is None or (args.times is not None and calls >= args.times):
            return 0
        time.sleep(max(0.0, last_call + period - time.monotonic()))
