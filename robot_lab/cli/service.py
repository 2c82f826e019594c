"""`robot-lab service list|type|find|info|call|echo`: prints what `ros2 service …` (Jazzy)
prints."""

from __future__ import annotations

import argparse
import sys
import time

from robot_lab.cli import print_names, run_sub_verb
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


    echo = sub.add_parser('echo', help='Echo a service')
    echo.add_argument('service_name',
                      help="Name of the ROS service to echo (e.g. '/add_two_ints')")
    echo.add_argument('service_type', nargs='?',
                      help="Type of the ROS service (e.g. 'example_interfaces/srv/AddTwoInts')")
    echo.add_argument('--csv', action='store_true', default=False,
                      help='Output all recursive fields separated by commas (e.g. for plotting).')
    echo.add_argument('--full-length', '-f', action='store_true',
                      help='Output all elements for arrays, bytes, and string with a length > '
                      "'--truncate-length', by default they are truncated")
    echo.add_argument('--truncate-length', '-l', type=int, default=128,
                      help='The length to truncate arrays, bytes, and string to (default: 128)')
    echo.add_argument('--no-arr', action='store_true', help="Don't print array fields of messages")
    echo.add_argument('--no-str', action='store_true',
                      help="Don't print string fields of messages")
    echo.add_argument('--flow-style', action='store_true',
                      help='Print collections in the block style (not available with csv format)')
    echo.add_argument('-n', '--times', type=int, default=None, metavar='N',
                      help='stop after N events (robot_lab; ros2cli runs until Ctrl-C)')


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.service_verb, {
        'list': _list, 'type': _type, 'find': _find, 'info': _info, 'call': _call, 'echo': _echo,
    })


def _typed(args: argparse.Namespace) -> list[tuple[str, list[str]]]:
    from robot_lab.graph.services import service_list_typed

    hidden = args.include_hidden_services
    found = ask_daemon(args, 'service_list', include_hidden=hidden)
    if found is None:
        found = service_list_typed(include_hidden=hidden)
    return [(name, list(types)) for name, types in found]


def _list(args: argparse.Namespace) -> int:
    print_names(_typed(args), count=args.count_services, show_types=args.show_types)
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
    from robot_lab.graph.services import ServiceInfo, service_info

    answer = ask_daemon(args, 'service_info', name=args.service_name)
    # GraphError: Unknown service '/x' (from the daemon too)
    info = ServiceInfo(**answer) if answer is not None else service_info(args.service_name)
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


def _echo(args: argparse.Namespace) -> int:
    """ros2service's echo: the service's `<name>/_service_event` topic (service
    introspection, off unless the server or client turns it on), one YAML event each."""
    from rclpy.qos import qos_profile_services_default
    from service_msgs.msg import ServiceEventInfo

    from robot_lab.errors import GraphError
    from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session, wait_until
    from robot_lab.graph.services import service_list_typed
    from robot_lab.graph.topics import echo_stream
    from robot_lab.messages import dict_to_yaml, message_class, message_to_csv, message_to_dict

    name = absolute_name(args.service_name)
    sess = get_session(None)
    kind = args.service_type
    if kind is None:
        kind = wait_until(lambda: next((t[0] for n, t in service_list_typed(
            include_hidden=True, settle=False, session=sess) if n == name and t), None),
            LOOKUP_TIMEOUT)
        if kind is None:
            raise GraphError('Could not load the type for the passed service',
                             fix=f'check the name with `robot-lab service list`, or give the '
                             f'type: `robot-lab service echo {name} std_srvs/srv/SetBool`')
    try:
        message_class(kind)
        event_type = f'{kind}_Event'
        message_class(event_type)
    except GraphError:
        raise GraphError(f"The service type '{kind}' is invalid") from None
    topic = f'{name}/_service_event'
    names = {value: key for key, value in vars(ServiceEventInfo).items()
             if key.isupper() and isinstance(value, int)}
    limit = None if args.full_length else args.truncate_length
    stream = echo_stream(topic, event_type, session=sess, qos=qos_profile_services_default)
    if wait_until(lambda: sess.node.count_publishers(topic) or None, LOOKUP_TIMEOUT) is None:
        print(f"No publishers on topic '{topic}'; "
              'is service introspection on the client or server enabled?', flush=True)
    for shown, event in enumerate(stream, start=1):
        if args.csv:
            print(message_to_csv(event, no_arr=args.no_arr, no_str=args.no_str,
                                 truncate_length=limit), flush=True)
        else:
            data = message_to_dict(event, no_arr=args.no_arr, no_str=args.no_str,
                                   truncate_length=limit)
            info = data.get('info')
            if isinstance(info, dict) and info.get('event_type') in names:
                info['event_type'] = names[info['event_type']]
            print(dict_to_yaml(data, flow_style=args.flow_style) + '---', flush=True)
        if args.times is not None and shown >= args.times:
            break
    return 0
