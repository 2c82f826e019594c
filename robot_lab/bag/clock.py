"""A playback as a ROS time source: rosbag2's `--clock [HZ]`, `--clock-topics`,
`--clock-topics-all`.

Nodes started with `use_sim_time:=true` take their time from `/clock`
(rosgraph_msgs/Clock). The player publishes its bag time there: `hz` times a second of
wall time (paused, the time stands still), and/or just before each replayed message of
the trigger topics (all topics with `--clock-topics-all`). QoS as rclcpp's ClockQoS:
keep last 1, best effort.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rclpy.node import Node

__all__ = ['ClockPublisher']


class ClockPublisher:
    """Publishes a player's bag time on /clock: periodically (`start`) and on demand."""

    def __init__(self, node: Node, now: Callable[[], int], hz: float = 0.0,
                 topics: Iterable[str] = (), all_topics: bool = False) -> None:
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock

        self._clock_cls = Clock
        self._publisher = node.create_publisher(
            Clock, '/clock', QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
        self._now = now
        self.hz = float(hz)
        self.trigger_topics = frozenset(t if t.startswith('/') else '/' + t for t in topics)
        self.all_topics = all_topics
        self.published = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def publish(self, stamp_ns: int) -> None:
        msg = self._clock_cls()
        msg.clock.sec, msg.clock.nanosec = divmod(max(0, int(stamp_ns)), 1_000_000_000)
        self._publisher.publish(msg)
        self.published += 1

    def before_message(self, topic: str, stamp_ns: int) -> None:
        """rosbag2's pre-publish callback: a clock update before a trigger topic's message."""
        if self.all_topics or topic in self.trigger_topics:
            self.publish(stamp_ns)

    def start(self) -> None:
        """Publish `hz` times a second until `stop()` (nothing when hz is 0)."""
        if self.hz <= 0 or self._thread is not None:
            return
        period = 1.0 / self.hz

        def run() -> None:
            while not self._stop.is_set():
                self.publish(self._now())
                self._stop.wait(period)

        self._thread = threading.Thread(target=run, name='robot_lab-bag-clock', daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)

    def destroy(self, node: Node) -> None:
        self.stop()
        node.destroy_publisher(self._publisher)
