"""A topic's bandwidth and header delay (`ros2 topic bw`, `ros2 topic delay`).

The meters follow ros2topic's definitions: bw sums the serialized (CDR) sizes of the last
`window` messages over the time since the first of them; delay is the receive time minus
`header.stamp`, the first message only starting the clock. `topic hz` lives in `topics`.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session
from robot_lab.graph.topics import _resolve_type, _without_qos_events

if TYPE_CHECKING:
    from robot_lab.rclpy_session import Session

__all__ = [
    'BandwidthMeter',
    'BwStats',
    'DelayMeter',
    'DelayStats',
    'TopicMeter',
    'topic_bw',
    'topic_delay',
]

BW_WINDOW = 100  # ros2 topic bw's default window (messages)
DELAY_WINDOW = 10000  # ros2 topic delay's


def _size_text(value: float, unit: str) -> str:
    if unit == 'B':
        return f'{value:.0f} B'
    if unit == 'KB':
        return f'{value / 1000:.2f} KB'
    return f'{value / 1000 / 1000:.2f} MB'


@dataclass
class BwStats:
    """Bytes per second over the window, and message sizes (bytes, serialized CDR)."""

    bytes_per_s: float
    messages: int
    mean: float
    min: int
    max: int

    def __str__(self) -> str:
        # ros2cli picks one unit by the rate and uses it for the sizes too.
        unit = 'B' if self.bytes_per_s < 1000 else 'KB' if self.bytes_per_s < 1e6 else 'MB'
        rate, mean, low, high = (_size_text(v, unit) for v in
                                 (self.bytes_per_s, self.mean, self.min, self.max))
        return (f'{rate}/s from {self.messages} messages\n'
                f'\tMessage size mean: {mean} min: {low} max: {high}')


class BandwidthMeter:
    """Arrival times and sizes of the last `window` raw messages."""

    def __init__(self, window: int = BW_WINDOW) -> None:
        self._lock = threading.Lock()
        self._seen: deque[tuple[int, int]] = deque(maxlen=window)
        self.count = 0

    def tick(self, data: bytes, now_ns: int | None = None) -> None:
        now = time.monotonic_ns() if now_ns is None else now_ns
        with self._lock:
            self._seen.append((now, len(data)))
            self.count += 1

    def stats(self, now_ns: int | None = None) -> BwStats | None:
        """None until two messages arrived (as ros2cli prints nothing before)."""
        now = time.monotonic_ns() if now_ns is None else now_ns
        with self._lock:
            seen = list(self._seen)
        if len(seen) < 2 or now <= seen[0][0]:
            return None
        sizes = [size for _, size in seen]
        total = sum(sizes)
        return BwStats(bytes_per_s=total / ((now - seen[0][0]) * 1e-9), messages=len(sizes),
                       mean=total / len(sizes), min=min(sizes), max=max(sizes))


@dataclass
class DelayStats:
    """Mean, min, max and std dev (s) of receive time minus header.stamp."""

    mean: float
    min: float
    max: float
    std_dev: float
    window: int

    def __str__(self) -> str:
        return (f'average delay: {self.mean:.3f}\n\tmin: {self.min:.3f}s max: {self.max:.3f}s '
                f'std dev: {self.std_dev:.5f}s window: {self.window}')


class DelayMeter:
    """Delays of the last `window` stamped messages (system clock, as ros2cli's node)."""

    def __init__(self, window: int = DELAY_WINDOW) -> None:
        self._lock = threading.Lock()
        self._delays: deque[int] = deque(maxlen=window)
        self._started = False
        self.count = 0

    def tick(self, msg: Any, now_ns: int | None = None) -> None:
        now = time.time_ns() if now_ns is None else now_ns
        stamp = msg.header.stamp
        with self._lock:
            self.count += 1
            if not self._started:  # ros2cli: the first message only starts the clock
                self._started = True
                return
            self._delays.append(now - (stamp.sec * 1_000_000_000 + stamp.nanosec))

    def stats(self) -> DelayStats | None:
        with self._lock:
            delays = list(self._delays)
        if not delays:
            return None
        n = len(delays)
        mean = sum(delays) / n
        std = math.sqrt(sum((d - mean) ** 2 for d in delays) / n)
        return DelayStats(mean=mean * 1e-9, min=min(delays) * 1e-9, max=max(delays) * 1e-9,
                          std_dev=std * 1e-9, window=n)


class TopicMeter:
    """A meter fed by a sensor-data subscription of the session; close() ends it."""

    def __init__(self, sess: Session, topic: str, cls: Any, meter: Any, raw: bool) -> None:
        from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
        from rclpy.qos import qos_profile_sensor_data

        self.meter = meter
        self.topic = topic
        self._sess = sess
        self._sub = sess.node.create_subscription(
            cls, topic, meter.tick, qos_profile_sensor_data, raw=raw,
            callback_group=MutuallyExclusiveCallbackGroup(), event_callbacks=_without_qos_events(),
        )

    def close(self) -> None:
        self._sess.node.destroy_subscription(self._sub)

    @classmethod
    def bandwidth(cls, name: str, window: int = BW_WINDOW, type_timeout: float = LOOKUP_TIMEOUT,
                  session: Session | None = None) -> TopicMeter:
        sess = get_session(session)
        topic = absolute_name(name)
        msg_class = _resolve_type(sess, topic, None, type_timeout)
        return cls(sess, topic, msg_class, BandwidthMeter(window), raw=True)

    @classmethod
    def delay(cls, name: str, window: int = DELAY_WINDOW, type_timeout: float = LOOKUP_TIMEOUT,
              session: Session | None = None) -> TopicMeter:
        sess = get_session(session)
        topic = absolute_name(name)
        msg_class = _resolve_type(sess, topic, None, type_timeout)
        if 'header' not in msg_class.get_fields_and_field_types():
            raise GraphError(
                f'msg does not have header: {topic} carries {msg_class.__module__.split(".")[0]}'
                f'/msg/{msg_class.__name__}',
                fix='topic delay needs a stamped type (one with a std_msgs/Header `header`)',
            )
        return cls(sess, topic, msg_class, DelayMeter(window), raw=False)


def _measure(meter: TopicMeter, duration: float) -> Any:
    try:
        time.sleep(duration)
    finally:
        meter.close()
    stats = meter.meter.stats()
    if stats is None:
        raise GraphError(
            f'fewer than 2 messages on {meter.topic} in {duration:g} s: nothing to report',
            fix=f'is anything publishing? `robot-lab topic info -v {meter.topic}`',
        )
    return stats


def topic_bw(topic: str, duration: float = 3.0, window: int = BW_WINDOW,
             session: Session | None = None) -> BwStats:
    """Measure `topic`'s bandwidth for `duration` seconds (ros2 topic bw's numbers)."""
    stats: BwStats = _measure(TopicMeter.bandwidth(topic, window, session=session), duration)
    return stats


def topic_delay(topic: str, duration: float = 3.0, window: int = DELAY_WINDOW,
                session: Session | None = None) -> DelayStats:
    """Measure how old `topic`'s messages are on arrival (now - header.stamp), in seconds."""
    stats: DelayStats = _measure(TopicMeter.delay(topic, window, session=session), duration)
    return stats
