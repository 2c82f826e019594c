"""`robot-lab demo [--duration S]`: the kit's three-node system, headless, for a terminal.

Runs `robot_lab robot.launch.xml` with its real output until an observer on the ROS graph
sees its three nodes, lets it run S seconds more, then stops it as Ctrl-C would and prints
what the observer saw: the nodes and the messages on the system's two topics. Exit code 0
when all three nodes were seen talking. The S seconds start when the nodes are up, not at
launch: on a loaded machine the nodes' imports alone can take longer than S.
"""

from __future__ import annotations

import argparse
import functools
import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.subscription import Subscription
    from std_msgs.msg import Float32, String


HELP = "Run the kit's robot system for a few seconds and summarise what it did"

_NODES = ('/controller', '/robot', '/sensor')
# The longest the demo waits for the nodes to appear before its S seconds start anyway.
_NODES_TIMEOUT = 60.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--duration', type=float, default=6.0, metavar='S',
                        help='seconds to run before shutting down (default: 6)')
    parser.add_argument('--robot-name', default=None,
                        help='robot_name launch argument (default: the launch file default)')


@dataclass
class _Observer:
    """Counts what the system publishes, from a participant started before the launch."""

    counts: dict[str, int] = field(default_factory=dict)
    last: dict[str, object] = field(default_factory=dict)
    nodes: list[str] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def subscribe(self, node: Node) -> list[Subscription]:
        from std_msgs.msg import Float32, String

        subs = []
        for topic, msg_type in (('/sensor/temperature', Float32), ('/robot/status', String)):
            subs.append(node.create_subscription(
                msg_type, topic, functools.partial(self._count, topic), 10))
        return subs

    def _count(self, topic: str, msg: Float32 | String) -> None:
        with self.lock:
            self.counts[topic] = self.counts.get(topic, 0) + 1
            self.last[topic] = msg.data

    def snapshot_nodes(self, node: Node) -> None:
        names = node.get_node_names_and_namespaces()
        self.nodes = sorted(
            (ns.rstrip('/') + '/' + name) for name, ns in names if not name.startswith('_')
        )

    def wait_for_nodes(self, node: Node, ended: threading.Event, timeout: float) -> bool:
        """Until the graph shows all of the system's nodes (True), or the launch ended or
        `timeout` passed (False)."""
        from robot_lab.graph.discovery import wait_until

        def probe() -> bool | None:
            self.snapshot_nodes(node)
            if ended.is_set():
                return False
            return True if all(name in self.nodes for name in _NODES) else None

        return bool(wait_until(probe, timeout))


def main(args: argparse.Namespace) -> int:
    from robot_lab.cli.launch import run
    from robot_lab.launch.resolve import describe_launch
    from robot_lab.launch.supervisor import Supervisor
    from robot_lab.rclpy_session import session

    launch_args = {'robot_name': args.robot_name} if args.robot_name else {}
    plan = describe_launch('robot_lab', 'robot.launch.xml', launch_args)
    ros = session()
    observer = _Observer()
    subscriptions = observer.subscribe(ros.node)
    ended = threading.Event()

    def stop_later(supervisor: Supervisor) -> None:
        def stopper() -> None:
            # The clock starts once the nodes are up: their imports alone may take seconds.
            observer.wait_for_nodes(ros.node, ended, _NODES_TIMEOUT)
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
