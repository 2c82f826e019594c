"""`robot-lab demo [--duration S]`: the kit's three-node system, headless, for a terminal.

Runs `robot_lab robot.launch.xml` for S seconds with its real output, then stops it as
Ctrl-C would and prints what an observer on the ROS graph saw: the nodes and the
messages on the system's two topics. Exit code 0 when all three nodes were seen talking.
"""

from __future__ import annotations

import argparse
import threading
from dataclasses import dataclass, field
from typing import Any

HELP = "Run the kit's robot system for a few seconds and summarise what it did"

_NODES = ('/controller', '/robot', '/sensor')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--duration', type=float, default=6.0, metavar='S',
                        help='seconds to run before shutting down (default: 6)')
    parser.add_argument('--robot-name', default=None,
                        help='robot_name launch argument (default: the launch file default)')


@dataclass
class _Observer:
    """Counts what the system publishes, from a participant started before the launch."""

    counts: dict[str, int] = field(default_factory=dict)
    last: dict[str, Any] = field(default_factory=dict)
    nodes: list[str] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def subscribe(self, node: Any) -> list[Any]:
        from std_msgs.msg import Float32, String

        subs = []
        for topic, msg_type in (('/sensor/temperature', Float32), ('/robot/status', String)):
            subs.append(node.create_subscription(
                msg_type, topic, lambda msg, topic=topic: self._count(topic, msg.data), 10))
        return subs

    def _count(self, topic: str, value: Any) -> None:
        with self.lock:
            self.counts[topic] = self.counts.get(topic, 0) + 1
            self.last[topic] = value

    def snapshot_nodes(self, node: Any) -> None:
        names = node.get_node_names_and_namespaces()
        self.nodes = sorted(
            (ns.rstrip('/') + '/' + name) for name, ns in names if not name.startswith('_')
        )


def main(args: argparse.Namespace) -> int:
    from robot_lab.cli.launch import run
    from robot_lab.context import session
    from robot_lab.launch.describe import describe_launch
    from robot_lab.launch.supervisor import Supervisor

    launch_args = {'robot_name': args.robot_name} if args.robot_name else {}
    plan = describe_launch('robot_lab', 'robot.launch.xml', launch_args)
    ros = session()
    observer = _Observer()
    subscriptions = observer.subscribe(ros.node)
    ended = threading.Event()

    def stop_later(supervisor: Supervisor) -> None:
        def stopper() -> None:
            if ended.wait(args.duration):
                return  # the launch ended (Ctrl-C) before the demo's time was up
            observer.snapshot_nodes(ros.node)
            supervisor.shutdown('demo finished')

        threading.Thread(target=stopper, name='robot_lab-demo-timer', daemon=True).start()

    try:
        run(plan, noninteractive=True, on_start=stop_later)
    finally:
        ended.set()
        for sub in subscriptions:
            ros.node.destroy_subscription(sub)
    return _summary(observer, args.duration)


def _summary(observer: _Observer, duration: float) -> int:
    print()
    print(f'Demo summary ({duration:g} s, seen by an observer node started first):')
    print('  nodes seen: ' + (', '.join(observer.nodes) or '(none)'))
    with observer.lock:
        for topic in ('/sensor/temperature', '/robot/status'):
            count = observer.counts.get(topic, 0)
            last = observer.last.get(topic)
            shown = '' if last is None else (
                f', last {last:.2f}' if isinstance(last, float) else f", last '{last}'")
            print(f'  {topic}: {count} messages{shown}')
        talking = all(observer.counts.get(t, 0) > 0
                      for t in ('/sensor/temperature', '/robot/status'))
    complete = all(name in observer.nodes for name in _NODES)
    return 0 if talking and complete else 1
