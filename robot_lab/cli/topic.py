"""`robot-lab topic list|info|type|echo|hz|pub`: prints what `ros2 topic …` (Jazzy) prints.

Beyond ros2cli: `echo --times N` (`-n N`) stops after N messages, and `hz --duration S`
stops after S seconds (ros2cli runs until Ctrl-C).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from typing import Any

from robot_lab.cli import print_names, run_sub_verb
from robot_lab.cli.daemon import add_no_daemon, ask_daemon

HELP = 'Various topic related sub-commands'

DEFAULT_TRUNCATE_LENGTH = 128


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value <= 0:
        raise argparse.ArgumentTypeError('value must be a positive integer')
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError('Expects a floating point number') from None
    if value <= 0.0:
        raise argparse.ArgumentTypeError('Value must be positive')
    return value


def _nonnegative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError('Value must be positive or zero')
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--include-hidden-topics', action='store_true',
                        help='Consider hidden topics as well')
    sub = parser.add_subparsers(dest='topic_verb', metavar='VERB')

    lister = sub.add_parser('list', help='Output a list of available topics')
    lister.add_argument('-t', '--show-types', action='store_true',
                        help='Additionally show the topic type')
    lister.add_argument('-c', '--count-topics', action='store_true',
                        help='Only display the number of topics discovered')
    lister.add_argument('-a', '--include-hidden-topics', dest='list_hidden', action='store_true',
                        help='Consider hidden topics as well')
    lister.add_argument('-v', '--verbose', action='store_true',
                        help='List full details about each topic')
    add_no_daemon(lister)

    info = sub.add_parser('info', help='Print information about a topic')
    info.add_argument('topic_name', help="Name of the ROS topic to get info (e.g. '/chatter')")
    info.add_argument('--verbose', '-v', action='store_true',
                      help='Prints detailed information like the node name, node namespace, '
                      'topic type, GUID and QoS Profile of the publishers and subscribers')

    kind = sub.add_parser('type', help="Print a topic's type")
    kind.add_argument('topic_name', help="Name of the ROS topic to get type (e.g. '/chatter')")

    echo = sub.add_parser('echo', help='Output messages from a topic')
    echo.add_argument('topic_name', help="Name of the ROS topic to listen to (e.g. '/chatter')")
    echo.add_argument('message_type', nargs='?',
                      help="Type of the ROS message (e.g. 'std_msgs/msg/String')")
    echo.add_argument('--field', type=str, default=None,
                      help="Echo a selected field of a message. Use '.' to select sub-fields")
    echo.add_argument('--full-length', '-f', action='store_true',
                      help='Output all elements for arrays, bytes, and strings')
    echo.add_argument('--truncate-length', '-l', type=_nonnegative_int,
                      default=DEFAULT_TRUNCATE_LENGTH,
                      help=f'The length to truncate arrays, bytes, and string to '
                      f'(default: {DEFAULT_TRUNCATE_LENGTH})')
    echo.add_argument('--no-arr', action='store_true', help="Don't print array fields of messages")
    echo.add_argument('--no-str', action='store_true',
                      help="Don't print string fields of messages")
    echo.add_argument('--csv', action='store_true',
                      help='Output all recursive fields separated by commas (e.g. for plotting)')
    echo.add_argument('--flow-style', action='store_true',
                      help='Print collections in the block style (not available with csv format)')
    echo.add_argument('--no-lost-messages', action='store_true',
                      help="Don't report when a message is lost")
    echo.add_argument('--raw', action='store_true', help='Echo the raw binary representation')
    echo.add_argument('--filter', dest='filter_expr',
                      help='Python expression to filter messages that are printed. Expression '
                      'can use Python builtins as well as m (the message).')
    echo.add_argument('--include-message-info', '-i', action='store_true',
                      help='Shows the associated message info.')
    echo.add_argument('--once', action='store_true',
                      help='Print the first message received and then exit.')
    echo.add_argument('--times', '-n', type=_positive_int, default=None, metavar='N',
                      help='Print N messages and then exit (robot_lab)')
    echo.add_argument('--timeout', metavar='N', type=_positive_float, default=None,
                      help='Set a timeout in seconds for waiting')

    hz = sub.add_parser('hz', help='Print the average publishing rate to screen')
    hz.add_argument('topic_name', help="Name of the ROS topic to listen to (e.g. '/chatter')")
    hz.add_argument('--window', '-w', dest='window_size', type=_positive_int, default=10000,
                    metavar='WINDOW', help='window size, in # of messages, for calculating '
                    'rate (default: 10000)')
    hz.add_argument('--duration', type=_positive_float, default=None, metavar='S',
                    help='stop after S seconds (robot_lab; ros2cli runs until Ctrl-C)')

    bw = sub.add_parser('bw', help='Display bandwidth used by topic')
    bw.add_argument('topic', help='Topic name to monitor for bandwidth utilization')
    bw.add_argument('--window', '-w', type=_positive_int, default=100, metavar='WINDOW',
                    help='maximum window size, in # of messages, for calculating rate '
                    '(default: 100)')
    bw.add_argument('--duration', type=_positive_float, default=None, metavar='S',
                    help='stop after S seconds (robot_lab; ros2cli runs until Ctrl-C)')

    delay = sub.add_parser('delay', help='Display delay of topic from timestamp in header')
    delay.add_argument('topic', help='Topic name to calculate the delay for')
    delay.add_argument('--window', '-w', type=_positive_int, default=10000,
                       help='window size, in # of messages, for calculating rate, '
                       'string to (default: 10000)')
    delay.add_argument('--duration', type=_positive_float, default=None, metavar='S',
                       help='stop after S seconds (robot_lab; ros2cli runs until Ctrl-C)')

    find = sub.add_parser('find', help='Output a list of available topics of a given type')
    find.add_argument('topic_type', help="Name of the ROS topic type to filter for "
                      "(e.g. 'std_msg/msg/String')")
    find.add_argument('-c', '--count-topics', action='store_true',
                      help='Only display the number of topics discovered')
    find.add_argument('--include-hidden-topics', dest='find_hidden', action='store_true',
                      help='Consider hidden topics as well')
    add_no_daemon(find)

    pub = sub.add_parser('pub', help='Publish a message to a topic')
    pub.add_argument('topic_name', help="Name of the ROS topic to publish to (e.g. '/chatter')")
    pub.add_argument('message_type', help="Type of the ROS message (e.g. 'std_msgs/String')")
    pub.add_argument('values', nargs='?', default='{}',
                     help="Values to fill the message with in YAML format (e.g. 'data: Hello "
                     "World'), otherwise the message will be published with default values")
    pub.add_argument('-r', '--rate', metavar='N', type=_positive_float, default=1.0,
                     help='Publishing rate in Hz (default: 1)')
    pub.add_argument('-p', '--print', metavar='N', type=int, default=1,
                     help='Only print every N-th published message (default: 1)')
    once = pub.add_mutually_exclusive_group()
    once.add_argument('-1', '--once', action='store_true', help='Publish one message and exit')
    once.add_argument('-t', '--times', type=_nonnegative_int, default=0,
                      help='Publish this number of times and then exit')
    pub.add_argument('-w', '--wait-matching-subscriptions', type=_nonnegative_int, default=None,
                     help='Wait until finding the specified number of matching subscriptions. '
                     'Defaults to 1 when using "-1"/"--once"/"--times", otherwise defaults to 0.')
    pub.add_argument('--max-wait-time-secs', type=_positive_float, default=None,
                     help='The maximum wait time in seconds for --wait-matching-subscriptions')
    pub.add_argument('--keep-alive', metavar='N', type=_positive_float, default=0.1,
                     help='Keep publishing node alive for N seconds after the last msg '
                     '(default: 0.1)')
    _add_qos_arguments(pub, 'publish', 'default')
    _add_qos_arguments(echo, 'subscribe', 'sensor_data')


# rclpy's short keys (QoSPresetProfiles.short_keys() etc.), listed here so that --help and
# argument errors need no rclpy import.
QOS_PROFILES = ['unknown', 'default', 'system_default', 'sensor_data', 'services_default',
                'parameters', 'parameter_events', 'action_status_default', 'best_available']
QOS_RELIABILITY = ['system_default', 'reliable', 'best_effort', 'unknown', 'best_available']
QOS_DURABILITY = ['system_default', 'transient_local', 'volatile', 'unknown', 'best_available']
QOS_HISTORY = ['system_default', 'keep_last', 'keep_all', 'unknown']
QOS_LIVELINESS = ['system_default', 'automatic', 'manual_by_topic', 'unknown', 'best_available']


def _add_qos_arguments(parser: argparse.ArgumentParser, verb: str, default: str) -> None:
    """ros2topic's --qos-* options (same names, choices and help)."""
    parser.add_argument('--qos-profile', choices=QOS_PROFILES, default=default,
                        help=f'Quality of service preset profile to {verb} with '
                        f'(default: {default})')
    parser.add_argument('--qos-depth', metavar='N', type=int,
                        help=f'Queue size setting to {verb} with '
                        '(overrides depth value of --qos-profile option)')
    parser.add_argument('--qos-history', choices=QOS_HISTORY,
                        help=f'History of samples setting to {verb} with '
                        '(overrides history value of --qos-profile option, default: keep_last)')
    compatible = 'default: Compatible profile with running endpoints )'
    parser.add_argument('--qos-reliability', choices=QOS_RELIABILITY,
                        help=f'Quality of service reliability setting to {verb} with '
                        f'(overrides reliability value of --qos-profile option, {compatible}')
    parser.add_argument('--qos-durability', choices=QOS_DURABILITY,
                        help=f'Quality of service durability setting to {verb} with '
                        f'(overrides durability value of --qos-profile option, {compatible}')
    parser.add_argument('--qos-liveliness', choices=QOS_LIVELINESS,
                        help=f'Quality of service liveliness setting to {verb} with '
                        '(overrides liveliness value of --qos-profile option')
    parser.add_argument('--qos-liveliness-lease-duration-seconds', type=float,
                        help=f'Quality of service liveliness lease duration setting to {verb} '
                        'with (overrides liveliness lease duration value of --qos-profile '
                        'option')


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.topic_verb, {
        'list': _list, 'info': _info, 'type': _type, 'echo': _echo, 'hz': _hz, 'pub': _pub,
        'bw': _bw, 'delay': _delay, 'find': _find,
    })


def _list(args: argparse.Namespace) -> int:
    from robot_lab.graph import api
    from robot_lab.graph.discovery import get_session

    hidden = args.include_hidden_topics or args.list_hidden
    if not args.verbose:  # -v counts endpoints per topic: that needs a session here
        answer = ask_daemon(args, 'topic_list', include_hidden=hidden)
        if answer is not None:
            _print_topics(args, [(name, list(types)) for name, types in answer])
            return 0
    sess = get_session(None)
    topics = api.topic_list(include_hidden=hidden, session=sess)
    if args.count_topics:
        print(len(topics))
    elif topics and args.verbose:
        for publishing in (True, False):
            lines = ['Published topics:' if publishing else 'Subscribed topics:']
            for name, types in topics:
                count = (sess.node.count_publishers(name) if publishing
                         else sess.node.count_subscribers(name))
                if count:
                    what = 'publisher' if publishing else 'subscriber'
                    lines.append(f' * {name} [{", ".join(types)}] {count} {what}'
                                 + ('s' if count > 1 else ''))
            print('\n'.join(lines) + '\n')
    else:
        _print_topics(args, topics)
    return 0


def _print_topics(args: argparse.Namespace, topics: list[tuple[str, list[str]]]) -> None:
    print_names(topics, count=args.count_topics, show_types=args.show_types)


def _info(args: argparse.Namespace) -> int:
    from robot_lab.graph import api

    answer = ask_daemon(args, 'topic_info', name=args.topic_name)
    if answer is not None:
        from robot_lab.graph.topics import Endpoint, TopicInfo

        info = TopicInfo(name=answer['name'], types=answer['types'],
                         publishers=[Endpoint(**e) for e in answer['publishers']],
                         subscribers=[Endpoint(**e) for e in answer['subscribers']])
    else:
        info = api.topic_info(args.topic_name, verbose=args.verbose)
    end = '\n\n' if args.verbose else '\n'
    type_text = info.types[0] if len(info.types) == 1 else str(info.types)
    print(f'Type: {type_text}', end=end)
    print(f'Publisher count: {len(info.publishers)}', end=end)
    if args.verbose:
        for endpoint in info.publishers:
            print(endpoint.text, end=end)
    print(f'Subscription count: {len(info.subscribers)}', end=end)
    if args.verbose:
        for endpoint in info.subscribers:
            print(endpoint.text, end=end)
    return 0


def _type(args: argparse.Namespace) -> int:
    from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session, wait_until
    from robot_lab.graph.topics import topic_list

    topic = absolute_name(args.topic_name)
    sess = get_session(None)

    def lookup() -> list[str] | None:
        found = dict(topic_list(include_hidden=True, session=sess))
        return found.get(topic)

    types = wait_until(lookup, LOOKUP_TIMEOUT)
    if types is None:
        return 1  # ros2cli prints nothing and exits 1
    for name in types:
        print(name)
    return 0


def _render(msg: Any, args: argparse.Namespace) -> str:
    from robot_lab.messages import message_to_csv, message_to_yaml

    if not hasattr(msg, 'get_fields_and_field_types'):
        return f'{msg}\n---'  # raw bytes or a selected primitive field, as Python prints it
    limit = None if args.full_length else args.truncate_length
    if args.csv:
        return message_to_csv(msg, no_arr=args.no_arr, no_str=args.no_str,
                              truncate_length=limit)
    text = message_to_yaml(msg, no_arr=args.no_arr, no_str=args.no_str, truncate_length=limit,
                           flow_style=args.flow_style)
    return f'{text}---'


def _echo_qos(args: argparse.Namespace) -> Any:
    """ros2topic echo's QoS: None (match the offers) unless a --qos-* override was given."""
    from robot_lab.graph.topics import qos_profile

    overrides = (args.qos_reliability, args.qos_durability, args.qos_depth, args.qos_history,
                 args.qos_liveliness, args.qos_liveliness_lease_duration_seconds)
    if all(value is None for value in overrides) and args.qos_profile == 'sensor_data':
        return None
    return qos_profile(args.qos_profile, reliability=args.qos_reliability,
                       durability=args.qos_durability, depth=args.qos_depth,
                       history=args.qos_history, liveliness=args.qos_liveliness,
                       lease_seconds=args.qos_liveliness_lease_duration_seconds)


def _message_filter(expr: str | None) -> Any:
    """`--filter 'm.data > 20'`: ros2cli evaluates the expression with the message as `m`."""
    if expr is None:
        return None
    code = compile(expr, '<--filter>', 'eval')

    def keep(m: Any) -> bool:
        return bool(eval(code, {}, {'m': m}))  # the user's own expression, as ros2cli
    return keep


def _echo(args: argparse.Namespace) -> int:
    import yaml

    from robot_lab.errors import GraphError
    from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session, wait_until
    from robot_lab.graph.topics import echo_stream, unknown_topic_fix
    from robot_lab.messages import field_value

    topic = absolute_name(args.topic_name)
    limit = 1 if args.once else args.times
    if args.field is not None and not [p for p in args.field.split('.') if p]:
        raise GraphError(f"Invalid field value '{args.field}'")
    keep = _message_filter(args.filter_expr)
    sess = get_session(None)
    if args.message_type is None:
        found = wait_until(
            lambda: next((t for n, t in sess.node.get_topic_names_and_types() if n == topic),
                         None), LOOKUP_TIMEOUT)
        if found is None:
            print(f'WARNING: topic [{topic}] does not appear to be published yet')
            raise GraphError(
                'Could not determine the type for the passed topic',
                fix=unknown_topic_fix(topic, sess.node.get_topic_names_and_types()),
            )
    stream = echo_stream(topic, args.message_type, timeout=args.timeout, session=sess,
                         raw=args.raw, with_info=args.include_message_info,
                         qos=_echo_qos(args))
    shown = 0
    for item in stream:
        msg, info = item if args.include_message_info else (item, None)
        if args.field and not args.raw:
            msg = field_value(msg, args.field)
        if keep is not None and not keep(msg):
            continue
        if info is not None:
            if not hasattr(msg, 'get_fields_and_field_types'):
                print('---Got new message, message info:---')
                print(info)
                print('---Message data:---')
            elif args.csv:
                print(','.join(str(v) for v in info.values()), end=',')
            else:
                print(yaml.dump(info), end='---\n')
        print(_render(msg, args), flush=True)
        shown += 1
        if limit is not None and shown >= limit:
            break
    return 0


def _meter_when_published(
        name: str, duration: float | None, open_meter: Callable[[str, Any], Any],
) -> tuple[Any, str, float | None] | None:
    """How hz, bw and delay start in ros2cli: the blocking type lookup (warn once, then
    wait for a publisher, bounded by --duration), then `open_meter(topic, session)`.

    Returns (meter, full topic name, when to stop), or None when the topic never came.
    """
    from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session, wait_until

    topic = absolute_name(name)
    sess = get_session(None)
    end = None if duration is None else time.monotonic() + duration

    def has_type() -> bool | None:
        return True if any(n == topic for n, _ in sess.node.get_topic_names_and_types()) else None

    if wait_until(has_type, LOOKUP_TIMEOUT) is None:
        print(f'WARNING: topic [{topic}] does not appear to be published yet', flush=True)
        remaining = None if end is None else max(0.0, end - time.monotonic())
        if wait_until(has_type, 1e9 if remaining is None else remaining) is None:
            return None
    return open_meter(topic, sess), topic, end


def _hz(args: argparse.Namespace) -> int:
    from robot_lab.graph.topics import rate_subscription

    started = _meter_when_published(
        args.topic_name, args.duration,
        lambda topic, sess: rate_subscription(topic, args.window_size, session=sess))
    if started is None:
        return 0
    meter, _topic, end = started
    try:
        # ros2cli prints about once a second of message time, starting a second after the
        # first interval was measured.
        first_seen: float | None = None
        last_print, printed_count = 0.0, 0
        while end is None or time.monotonic() < end:
            time.sleep(0.02)
            stats = meter.meter.stats()
            now = time.monotonic()
            if stats is None:
                continue
            if first_seen is None:
                first_seen = last_print = now
                continue
            # like ros2cli: nothing new printed while no new message arrived
            if now - last_print >= 1.0 and meter.meter.count != printed_count:
                print(stats, flush=True)
                last_print, printed_count = now, meter.meter.count
    finally:
        meter.close()
    return 0


def _every_second(meter: Any, end: float | None, report: Any) -> None:
    """Call `report()` once a second (ros2cli's 1 s timer) until `end`; close the meter."""
    try:
        tick = time.monotonic() + 1.0
        while end is None or tick <= end:
            time.sleep(max(0.0, tick - time.monotonic()))
            report()
            tick += 1.0
    finally:
        meter.close()


def _bw(args: argparse.Namespace) -> int:
    from robot_lab.graph.topic_stats import TopicMeter

    started = _meter_when_published(
        args.topic, args.duration,
        lambda topic, sess: TopicMeter.bandwidth(topic, args.window, session=sess))
    if started is None:
        return 0
    meter, topic, end = started
    print(f'Subscribed to [{topic}]', flush=True)

    def report() -> None:
        stats = meter.meter.stats()
        if stats is not None:
            print(stats, flush=True)

    _every_second(meter, end, report)
    return 0


def _delay(args: argparse.Namespace) -> int:
    from robot_lab.graph.topic_stats import TopicMeter

    started = _meter_when_published(
        args.topic, args.duration,
        lambda topic, sess: TopicMeter.delay(topic, args.window, session=sess))
    if started is None:
        return 0
    meter, _topic, end = started
    printed = [0]

    def report() -> None:
        stats = meter.meter.stats()
        if stats is None:
            return  # nothing measured yet: ros2cli stays silent
        if meter.meter.count == printed[0]:
            print('no new messages', flush=True)
            return
        printed[0] = meter.meter.count
        print(stats, flush=True)

    _every_second(meter, end, report)
    return 0


def _find(args: argparse.Namespace) -> int:
    from robot_lab.graph.topics import topic_find

    hidden = args.include_hidden_topics or args.find_hidden
    answer = ask_daemon(args, 'topic_list', include_hidden=hidden)
    if answer is not None:
        found = [name for name, types in answer if args.topic_type in types]
    else:
        found = topic_find(args.topic_type, include_hidden=hidden)
    if args.count_topics:
        print(len(found))
    else:
        for name in found:
            print(name)
    return 0


def _pub(args: argparse.Namespace) -> int:
    from robot_lab.graph.topics import open_publisher, qos_profile, wait_for_subscribers
    from robot_lab.messages import message_class, stamped_message_from_yaml

    times = 1 if args.once else args.times
    wait_for = (args.wait_matching_subscriptions if args.wait_matching_subscriptions is not None
                else int(times != 0))
    cls = message_class(args.message_type)  # GraphError: The passed message type is invalid
    # GraphError: needs a dictionary in YAML format / Failed to populate field
    msg, restamp = stamped_message_from_yaml(cls, args.values)
    qos = qos_profile(args.qos_profile, reliability=args.qos_reliability,
                      durability=args.qos_durability, depth=args.qos_depth,
                      history=args.qos_history, liveliness=args.qos_liveliness,
                      lease_seconds=args.qos_liveliness_lease_duration_seconds)
    pub = open_publisher(args.topic_name, args.message_type, qos=qos)
    if wait_for == 0 and args.max_wait_time_secs is not None:
        print('--max-wait-time-secs option is only effective with '
              '--wait-matching-subscriptions, --once or --times', file=sys.stderr)
        return 1
    if wait_for and not wait_for_subscribers(pub, wait_for, 0):
        print(f'Waiting for at least {wait_for} matching subscription(s)...', flush=True)
        start = time.monotonic()
        while not wait_for_subscribers(pub, wait_for, 1.0):
            if (args.max_wait_time_secs is not None
                    and time.monotonic() - start >= args.max_wait_time_secs):
                print(f'Timed out waiting for subscribers: Expected {wait_for} subcribers but '
                      f'only got {pub.get_subscription_count()} subscribers', file=sys.stderr)
                return 1
            print(f'Waiting for at least {wait_for} matching subscription(s)...', flush=True)
    print('publisher: beginning loop', flush=True)
    period = 1.0 / args.rate
    start = time.monotonic()
    count = 0
    while times == 0 or count < times:
        if count:
            delay = start + count * period - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        restamp()  # `header: auto` / `stamp: now`: the time of this publish, as ros2cli
        count += 1
        if args.print and count % args.print == 0:
            print(f'publishing #{count}: {msg!r}\n', flush=True)
        pub.publish(msg)
    time.sleep(args.keep_alive)  # let the last message reach the wire before the exit
    return 0
