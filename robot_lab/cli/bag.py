"""`robot-lab bag record|info|play|reindex`: the `ros2 bag` verbs, over robot_lab.bag."""

from __future__ import annotations

import argparse
import signal
import sys
import time
from collections.abc import Callable
from types import FrameType
from typing import TYPE_CHECKING

from robot_lab.cli import run_sub_verb

if TYPE_CHECKING:
    from robot_lab.bag.play import Player

HELP = 'Various rosbag related sub-commands'


def _positive_float(value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{value} is not the valid type (float)') from None
    if number <= 0.0:
        raise argparse.ArgumentTypeError(f'{value} is not in the valid range (> 0.0)')
    return number


def _not_negative_float(value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{value} is not the valid type (float)') from None
    if number < 0.0:
        raise argparse.ArgumentTypeError(f'Value {value} is less than zero.')
    return number


def _positive_int(value: str) -> int:
    try:
        number = int(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{value} is not the valid type (int)') from None
    if number <= 0:
        raise argparse.ArgumentTypeError(f'{value} is not in the valid range (> 0)')
    return number


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='bag_verb', metavar='Call `robot-lab bag <command> -h`')

    rec = sub.add_parser('record', help='Record ROS data to a bag')
    given = rec.add_mutually_exclusive_group()  # as rosbag2: positional or --topics
    given.add_argument('topics', nargs='*', default=[], metavar='[Topic ...]',
                       help='Space-delimited list of topics to record. (deprecated)')
    given.add_argument('--topics', dest='topics_opt', nargs='+', default=[], metavar='Topic',
                       help='Space-delimited list of topics to record.')
    rec.add_argument('-a', '--all', dest='all', action='store_true',
                     help='Record all topics and services (Exclude hidden topic).')
    rec.add_argument('--all-topics', action='store_true',
                     help='Record all topics (Exclude hidden topic).')
    rec.add_argument('--service', '--services', dest='services', nargs='+', default=[],
                     metavar='ServiceName',
                     help='Space-delimited list of services to record (their service '
                     'introspection events, which the server or client must turn on).')
    rec.add_argument('--all-services', action='store_true',
                     help='Record all services via service event topics.')
    rec.add_argument('-o', '--output',
                     help='Destination of the bagfile to create, defaults to a timestamped '
                     'folder in the current directory.')
    rec.add_argument('-s', '--storage', default='mcap', choices=['mcap', 'sqlite3'],
                     help="Storage identifier to be used, defaults to '%(default)s'.")
    rec.add_argument('-b', '--max-bag-size', type=int, default=0,
                     help='Maximum size in bytes before the bagfile will be split. '
                     'Default: %(default)d, recording written in single bagfile and splitting '
                     'is disabled.')
    rec.add_argument('-d', '--max-bag-duration', type=int, default=0,
                     help='Maximum duration in seconds before the bagfile will be split. '
                     'Default: %(default)d, recording written in single bagfile and splitting '
                     'is disabled. If both splitting by size and duration are enabled, the bag '
                     'will split at whichever threshold is reached first.')
    rec.add_argument('--duration', type=_positive_float, metavar='S',
                     help='Stop recording after S seconds (robot_lab extension).')
    rec.add_argument('--max-messages', type=_positive_int, metavar='N',
                     help='Stop recording after N messages in total (robot_lab extension).')
    _add_record_filters(rec)

    info = sub.add_parser('info', help='Print information about a bag to the screen')
    info.add_argument('bag_path', help='Bag to open')
    info.add_argument('-t', '--topic-name', action='store_true', help='Only display topic names.')
    info.add_argument('-v', '--verbose', action='store_true',
                      help='Display request/response information for services')

    play = sub.add_parser('play', help='Play back ROS data from a bag')
    play.add_argument('bag_path', help='Bag to open')
    play.add_argument('-r', '--rate', type=_positive_float, default=1.0,
                      help='rate at which to play back messages. Valid range > 0.0.')
    play.add_argument('-l', '--loop', action='store_true',
                      help='enables loop playback when playing a bagfile: it starts back at '
                      'the beginning on reaching the end and plays indefinitely.')
    play.add_argument('--topics', nargs='+', default=None, metavar='topic',
                      help='Space-delimited list of topics to play.')
    play.add_argument('--services', nargs='+', default=None, metavar='service',
                      help='Space-delimited list of services to play.')
    play.add_argument('-e', '--regex', default='',
                      help='Play only topics and services matches with regular expression.')
    play.add_argument('-x', '--exclude-regex', default='',
                      help='regular expressions to exclude topics and services from replay.')
    play.add_argument('--exclude-topics', nargs='+', default=[], metavar='topic',
                      help='Space-delimited list of topics not to play.')
    play.add_argument('--exclude-services', nargs='+', default=[], metavar='service',
                      help='Space-delimited list of services not to play.')
    play.add_argument('--remap', '-m', nargs='+', default=[],
                      help='list of topics to be remapped: in the form '
                      '"old_topic1:=new_topic1 old_topic2:=new_topic2 etc." ')
    clock = play.add_mutually_exclusive_group()
    clock.add_argument('--clock', type=_positive_float, nargs='?', const=40.0, default=0.0,
                       help='Publish to /clock at a specific frequency in Hz, to act as a ROS '
                       'Time Source. Value must be positive. Defaults to not publishing.')
    clock.add_argument('--clock-topics', nargs='+', default=[],
                       help='List of topics separated by spaces that will trigger a /clock '
                       'update when a message is published on them')
    clock.add_argument('--clock-topics-all', action='store_true',
                       help='Publishes an update on /clock immediately before each replayed '
                       'message')
    play.add_argument('--playback-duration', type=float, default=-1.0,
                      help='Playback duration, in seconds. Negative durations mark an infinite '
                      'playback. Default is -1. When positive, the maximum of '
                      '`playback-until-*` and the one that this attribute yields will be used '
                      'to determine which one stops playback execution.')
    until = play.add_mutually_exclusive_group()
    until.add_argument('--playback-until-sec', type=float, default=-1.0,
                       help='Playback until timestamp, expressed in seconds since epoch. '
                       'Mutually exclusive argument with `--playback-until-nsec`.')
    until.add_argument('--playback-until-nsec', type=int, default=-1,
                       help='Playback until timestamp, expressed in nanoseconds since epoch. '
                       'Mutually exclusive argument with `--playback-until-sec`.')
    # rosbag2's tuning options, accepted so tutorial command lines run; the kit reads the
    # storage format from the files and waits for acknowledgements by itself.
    play.add_argument('-s', '--storage', choices=['mcap', 'sqlite3'], default=None,
                      help='Storage implementation of bag. By default attempts to detect '
                      'automatically.')
    play.add_argument('--read-ahead-queue-size', type=int, default=1000,
                      help='size of message queue rosbag tries to hold in memory (accepted; '
                      'the kit reads the bag as it plays)')
    play.add_argument('--wait-for-all-acked', type=int, default=-1, metavar='TIMEOUT_MS',
                      help='Wait until all published messages are acknowledged (accepted; the '
                      'kit waits up to 1 s for reliable subscribers at the end)')
    play.add_argument('--disable-loan-message', action='store_true',
                      help='Disable to publish as loaned message (accepted; no loans here)')
    play.add_argument('--publish-service-requests', action='store_true', default=False,
                      help='Publish recorded service requests instead of recorded service '
                      'events')
    play.add_argument('--service-requests-source', default='service_introspection',
                      choices=['service_introspection', 'client_introspection'],
                      help='Determine the source of the service requests to be replayed. '
                      'This option only makes sense if the "--publish-service-requests" '
                      'option is set. By default, the service requests replaying from '
                      'recorded service introspection message.')
    play.add_argument('-p', '--start-paused', action='store_true', default=False,
                      help='Start the playback player in a paused state.')
    play.add_argument('--disable-keyboard-controls', action='store_true',
                      help='disables keyboard controls for playback')
    play.add_argument('-d', '--delay', type=_not_negative_float, default=0.0,
                      help='Sleep duration before play (each loop), in seconds. Negative '
                      'durations invalid.')
    play.add_argument('--qos-profile-overrides-path', metavar='PATH',
                      help='Path to a yaml file defining overrides of the QoS profile for '
                      'specific topics.')
    play.add_argument('--start-offset', type=_not_negative_float, default=0.0,
                      help='Start the playback player this many seconds into the bag file.')

    reindex = sub.add_parser('reindex', help='Reconstruct metadata file for a bag')
    reindex.add_argument('bag_path', help='Bag to open')


def _record_arguments_problem(args: argparse.Namespace, topics: list[str]) -> str:
    """ros2bag's checks of a record command line, in its order and words ('' if fine)."""
    every_topic = args.all or args.all_topics or args.topic_types or args.regex
    if not (every_topic or args.all_services or topics or args.services):
        return ('Need to specify at least one option out of --all, --all-topics, '
                '--all-services, --services, --topics, --topic-types or --regex')
    if args.exclude_regex and not (every_topic or args.all_services):
        return ('--exclude-regex argument requires either --all, --all-topics, '
                '--topic-types, --all-services or --regex')
    if args.exclude_topics and not every_topic:
        return ('--exclude-topics argument requires either --all, --all-topics, '
                '--topic-types or --regex')
    if args.exclude_topic_types and not every_topic:
        return '--exclude-topic-types argument requires either --all, --all-topics or --regex'
    if args.exclude_services and not (args.all or args.all_services or args.regex):
        return ('--exclude-services argument requires either --all, --all-services '
                'or --regex')
    return ''


def _add_record_filters(rec: argparse.ArgumentParser) -> None:
    """rosbag2's record selection and discovery options (robot_lab.bag.selection)."""
    rec.add_argument('--topic-types', nargs='+', default=[], metavar='TopicType',
                     help='Space-delimited list of topic types to record.')
    rec.add_argument('-e', '--regex', default='',
                     help='Record only topics and services containing provided regular '
                     'expression. Note: --all, --all-topics or --all-services will override '
                     '--regex.')
    rec.add_argument('--exclude-regex', default='',
                     help='Exclude topics and services containing provided regular '
                     'expression. Works on top of --all, --all-topics, --all-services, '
                     '--topics, --services or --regex.')
    rec.add_argument('--exclude-topic-types', nargs='+', default=[], metavar='ExcludeTopicTypes',
                     help='Space-delimited list of topic types not being recorded.')
    rec.add_argument('--exclude-topics', nargs='+', default=[], metavar='Topic',
                     help='Space-delimited list of topics not being recorded.')
    rec.add_argument('--exclude-services', nargs='+', default=[], metavar='ServiceName',
                     help='Space-delimited list of services not being recorded.')
    rec.add_argument('--include-unpublished-topics', action='store_true',
                     help='Discover and record topics which have no publisher. Subscriptions '
                     'on such topics will be made with default QoS unless otherwise specified '
                     'in a QoS overrides file.')
    rec.add_argument('--include-hidden-topics', action='store_true',
                     help='Discover and record hidden topics as well. These are topics used '
                     'internally by ROS 2 implementation.')
    rec.add_argument('--no-discovery', action='store_true',
                     help='Disables topic auto discovery during recording: only topics present '
                     'at startup will be recorded.')
    rec.add_argument('-p', '--polling-interval', type=int, default=100,
                     help='Time in ms to wait between querying available topics for '
                     'recording. It has no effect if --no-discovery is enabled.')
    rec.add_argument('--node-name', default='rosbag2_recorder',
                     help='Specify the recorder node name. Default is %(default)s.')
    # tuning rosbag2 offers, accepted so tutorial command lines run unchanged
    rec.add_argument('-f', '--serialization-format', default='cdr', choices=['cdr'],
                     help='The rmw serialization format in which the messages are saved '
                     '(cdr, the only one here).')
    rec.add_argument('--max-cache-size', type=int, default=100 * 1024 * 1024,
                     help='Maximum size (in bytes) of messages to hold in each buffer of cache '
                     '(accepted; the kit flushes every 0.5 s).')
    rec.add_argument('--disable-keyboard-controls', action='store_true', default=False,
                     help='disables keyboard controls for recorder')
    rec.add_argument('--qos-profile-overrides-path', metavar='PATH',
                     help='Path to a yaml file defining overrides of the QoS profile for '
                     'specific topics.')
    rec.add_argument('--start-paused', action='store_true', default=False,
                     help='Start the recorder in a paused state.')
    rec.add_argument('--custom-data', nargs='*', default=[], metavar='KEY=VALUE',
                     help='Space-delimited list of key=value pairs. Store the custom data in '
                     "metadata under the 'rosbag2_bagfile_information/custom_data'. The key=value "
                     'pair can appear more than once. The last value will override the former '
                     'ones.')
    rec.add_argument('--log-level', default='info',
                     choices=['debug', 'info', 'warn', 'error', 'fatal'],
                     help='Logging level (accepted).')


def _err(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def _interrupt_on_sigterm() -> None:
    """SIGTERM (and an inherited-ignored SIGINT) end a recording like Ctrl-C does."""

    def _raise(_sig: int, _frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _raise)


def _record(args: argparse.Namespace) -> int:
    from robot_lab.bag.record import Recorder

    topics = list(args.topics_opt or args.topics)
    problem = _record_arguments_problem(args, topics)
    if problem:
        _err(f'[ERROR] [ros2bag]: {problem}')
        return 1
    all_topics = args.all or args.all_topics
    all_services = args.all or args.all_services
    for overridden, message in (
            (all_services and args.services, '--all or --all-services will override --services'),
            (all_topics and topics, '--all or --all-topics will override --topics'),
            ((all_topics or all_services) and args.regex,
             '--all, --all-topics or --all-services will override --regex')):
        if overridden:
            _err(f'[WARN] [ros2bag]: {message}')
    _interrupt_on_sigterm()
    rec = Recorder(
        topics, all_topics=all_topics, output=args.output, storage=args.storage,
        duration=args.duration, max_messages=args.max_messages, log=_err,
        max_bag_size=args.max_bag_size, max_bag_duration=args.max_bag_duration,
        services=args.services, all_services=all_services, topic_types=args.topic_types,
        regex=args.regex, exclude_regex=args.exclude_regex,
        exclude_topic_types=args.exclude_topic_types, exclude_topics=args.exclude_topics,
        exclude_services=args.exclude_services,
        include_hidden_topics=args.include_hidden_topics,
        include_unpublished_topics=args.include_unpublished_topics,
        no_discovery=args.no_discovery, polling_interval=args.polling_interval / 1000.0,
        node_name=args.node_name, start_paused=args.start_paused,
        qos_overrides=args.qos_profile_overrides_path,
        custom_data=dict(item.split('=', 1) for item in args.custom_data if '=' in item),
    )
    rec.open()  # an existing output folder is refused before any key is announced
    from robot_lab.cli import keyboard

    # rosbag2's recorder announces its key before it listens for topics
    restore = keyboard.unchanged if args.disable_keyboard_controls else keyboard.listen(
        [(keyboard.SPACE, 'pausing/resuming', rec.toggle_paused)], rec.log, _err)
    try:
        rec.start()
    except BaseException:
        restore()
        raise
    try:
        while not rec.wait(0.1):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl-C must not cut the close
        rec.stop()
        restore()
    return 0


def _info(args: argparse.Namespace) -> int:
    from robot_lab.bag.info import (
        _is_service_event,
        bag_info,
        format_info,
        format_verbose,
        service_info,
    )

    if args.topic_name and args.verbose:
        print("Warning! You have set both the '-t' and '-v' parameters. The '-t' parameter "
              'will be ignored.')
    info = bag_info(args.bag_path)
    if args.verbose:
        print(format_verbose(info, service_info(args.bag_path)))
    elif args.topic_name:
        for topic in info.topics:
            if not _is_service_event(topic):
                print(topic.name)
    else:
        print(format_info(info))
    return 0


def _play(args: argparse.Namespace) -> int:
    from robot_lab.bag.play import Player

    _interrupt_on_sigterm()
    player = Player(
        args.bag_path, rate=args.rate, loop=args.loop, topics=args.topics,
        start_offset=args.start_offset, delay=args.delay, log=_err,
        qos_overrides=args.qos_profile_overrides_path, services=args.services,
        publish_service_requests=args.publish_service_requests,
        service_requests_source=args.service_requests_source, start_paused=args.start_paused,
        exclude_topics=args.exclude_topics, exclude_services=args.exclude_services,
        regex=args.regex, exclude_regex=args.exclude_regex, remap=args.remap,
        clock=args.clock, clock_topics=args.clock_topics,
        clock_topics_all=args.clock_topics_all, playback_duration=args.playback_duration,
        playback_until=(args.playback_until_nsec if args.playback_until_nsec >= 0
                        else int(args.playback_until_sec * 1e9)
                        if args.playback_until_sec >= 0 else -1),
    )
    player.open()  # a bag that cannot be played is refused before the keys are announced
    from robot_lab.cli import keyboard

    restore = keyboard.unchanged if args.disable_keyboard_controls else _play_keys(player)
    try:
        player.start()
        while not player.wait(0.1):
            pass
    except KeyboardInterrupt:
        player.stop()
    finally:
        restore()
    return 0


def _play_keys(player: Player) -> Callable[[], None]:
    """rosbag2's player keys: SPACE pauses/resumes, → publishes the next message while
    paused, ↑/↓ change the rate by 0.1."""
    from robot_lab.cli import keyboard

    player.log('INFO', 'Adding keyboard callbacks.')
    return keyboard.listen([
        (keyboard.SPACE, 'Pause/Resume', player.toggle_paused),
        (keyboard.CURSOR_RIGHT, 'Play Next Message', player.request_next),
        (keyboard.CURSOR_UP, 'Increase Rate 10%',
         lambda: player.set_rate(round(player.rate + 0.1, 6))),
        (keyboard.CURSOR_DOWN, 'Decrease Rate 10%',
         lambda: player.set_rate(round(player.rate - 0.1, 6))),
    ], player.log, _err)


def _reindex(args: argparse.Namespace) -> int:
    from robot_lab.bag.reindex import reindex

    started = time.monotonic()
    report = reindex(args.bag_path)
    cut = f', {report.truncated_bytes} bytes of an unfinished record dropped' \
        if report.truncated_bytes else ''
    counts = ', '.join(f'{t}: {n}' for t, n in report.counts.items()) or 'no topics'
    _err(f"[INFO] [ros2bag]: Reindexed '{report.path}' ({report.storage_id}): "
         f'{report.message_count} messages ({counts}){cut} in {time.monotonic() - started:.2f} s')
    return 0


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.bag_verb, {
        'record': _record, 'info': _info, 'play': _play, 'reindex': _reindex,
    })
