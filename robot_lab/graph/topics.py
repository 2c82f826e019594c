"""Topics: list, info, type, echo, hz and pub, through the session's hidden node."""

from __future__ import annotations

import copy
import math
import queue
import threading
import time
import weakref
from collections import deque
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import (
    LOOKUP_TIMEOUT,
    absolute_name,
    endpoints_attributed,
    get_session,
    settled,
    wait_until,
)
from robot_lab.graph.nodes import names_and_types
from robot_lab.messages import (
    field_value,
    message_class,
    stamped_message_from_yaml,
    type_name,
)

if TYPE_CHECKING:
    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.publisher import Publisher
    from rclpy.qos import QoSProfile
    from rclpy.topic_endpoint_info import TopicEndpointInfo

    from robot_lab.rclpy_session import Session

__all__ = [
    'Endpoint',
    'HzStats',
    'RateMeter',
    'TopicInfo',
    'echo',
    'echo_stream',
    'open_publisher',
    'publish',
    'qos_profile',
    'topic_find',
    'topic_hz',
    'topic_info',
    'topic_list',
    'topic_type',
    'unknown_topic_fix',
    'wait_for_subscribers',
    'wait_for_topic',
]

# ros2 topic hz's default window (messages)
DEFAULT_WINDOW = 10000


def _without_qos_events() -> SubscriptionEventCallbacks:
    """No QoS event handlers on our subscriptions: rclpy races when a subscription with
    handlers is destroyed while the executor thread builds its wait set."""
    from rclpy.event_handler import SubscriptionEventCallbacks

    return SubscriptionEventCallbacks(use_default_callbacks=False)


def topic_list(include_hidden: bool = False, *, settle: bool = True,
               session: Session | None = None) -> list[tuple[str, list[str]]]:
    """(name, types) of every topic, sorted by name (like `ros2 topic list -t`).

    With `settle` it first lets discovery finish, like `node_list`.
    """
    sess = get_session(session)
    return names_and_types(sess.node.get_topic_names_and_types, include_hidden, settle, sess)


def topic_find(msg_type: str, include_hidden: bool = False, *, settle: bool = True,
               session: Session | None = None) -> list[str]:
    """Topics of exactly type `msg_type`, sorted (`ros2 topic find`: the full name,
    `std_msgs/msg/String`, as the graph spells it)."""
    return [name for name, types in topic_list(include_hidden, settle=settle, session=session)
            if msg_type in types]


def unknown_topic_fix(topic: str, known: Iterable[tuple[str, list[str]]]) -> str:
    """The fix for a topic nobody publishes: the existing name it is closest to (a typo?),
    with that topic's real type; never a guessed type."""
    import difflib

    types = {name: kinds for name, kinds in known if name != topic}
    near = difflib.get_close_matches(topic, list(types), n=1, cutoff=0.75)
    if near:
        return (f'did you mean {near[0]} ({", ".join(types[near[0]])})? Names must match '
                'exactly: `robot-lab topic list` shows them')
    return ('check the name with `robot-lab topic list`, or give the type: '
            f'`robot-lab topic echo {topic} <package>/msg/<Type>`')


def _types_of(sess: Session, topic: str) -> list[str] | None:
    for name, types in sess.node.get_topic_names_and_types():
        if name == topic:
            return list(types)
    return None


def wait_for_topic(name: str, timeout: float = 10.0, session: Session | None = None) -> list[str]:
    """Block until `name` has a publisher or subscriber in the graph; returns its types."""
    sess = get_session(session)
    topic = absolute_name(name)
    types = wait_until(lambda: _types_of(sess, topic), timeout)
    if types is None:
        raise GraphError(
            f"topic '{topic}' did not appear within {timeout:g} s",
            fix='check the name with `robot-lab topic list` and that its publisher runs',
        )
    return types


def _unknown_topic(topic: str) -> GraphError:
    return GraphError(
        f"Unknown topic '{topic}'",
        fix='check the name with `robot-lab topic list` (is its node running?)',
    )


def topic_type(name: str, timeout: float = LOOKUP_TIMEOUT,
               session: Session | None = None) -> str:
    """The topic's message type, e.g. `std_msgs/msg/Float32` (waits briefly for discovery)."""
    sess = get_session(session)
    topic = absolute_name(name)
    types = wait_until(lambda: _types_of(sess, topic), timeout)
    if types is None:
        raise _unknown_topic(topic)
    if len(types) > 1:
        raise GraphError(
            f"topic '{topic}' has more than one type: [{', '.join(types)}]",
            fix='two nodes disagree on the type; fix the one that is wrong',
        )
    return types[0]


@dataclass
class Endpoint:
    """One publisher or subscription of a topic, as `ros2 topic info -v` lists it."""

    node_name: str
    node_namespace: str
    topic_type: str
    endpoint_type: str  # 'PUBLISHER' or 'SUBSCRIPTION'
    gid: str
    qos: dict[str, str]
    text: str  # the block `ros2 topic info -v` prints for it

    @property
    def node(self) -> str:
        return self.node_namespace.rstrip('/') + '/' + self.node_name


@dataclass
class TopicInfo:
    """A topic's types and who publishes and subscribes to it."""

    name: str
    types: list[str]
    publishers: list[Endpoint] = field(default_factory=list)
    subscribers: list[Endpoint] = field(default_factory=list)


def _endpoint(info: TopicEndpointInfo) -> Endpoint:
    qos = info.qos_profile
    return Endpoint(
        node_name=info.node_name,
        node_namespace=info.node_namespace,
        topic_type=info.topic_type,
        endpoint_type=info.endpoint_type.name,
        gid='.'.join(format(x, '02x') for x in info.endpoint_gid),
        qos={
            'reliability': qos.reliability.name,
            'history': qos.history.name,
            'depth': str(qos.depth),
            'durability': qos.durability.name,
            'liveliness': qos.liveliness.name,
        },
        text=str(info),
    )


def topic_info(name: str, verbose: bool = False, timeout: float = LOOKUP_TIMEOUT,
               session: Session | None = None) -> TopicInfo:
    """Types, publishers and subscribers (node names, QoS) of one topic.

    `verbose` is accepted for symmetry with `ros2 topic info -v`; the endpoints are always
    returned (the CLI decides what to print).
    """
    sess = get_session(session)
    topic = absolute_name(name)
    types = wait_until(lambda: _types_of(sess, topic), timeout)
    if types is None:
        raise _unknown_topic(topic)

    def probe() -> TopicInfo:
        return TopicInfo(
            name=topic,
            types=_types_of(sess, topic) or types,
            publishers=[_endpoint(i) for i in sess.node.get_publishers_info_by_topic(topic)],
            subscribers=[_endpoint(i) for i in sess.node.get_subscriptions_info_by_topic(topic)],
        )

    # A fresh session may know one end of the topic and not yet the other, or an endpoint
    # and not yet its node (`_NODE_NAME_UNKNOWN_` in `topic info -v`).
    return settled(sess, probe, ready=endpoints_attributed(sess, topic))


def _echo_qos(sess: Session, topic: str) -> QoSProfile:
    """ros2 topic echo's choice: sensor-data QoS, made reliable / transient-local only when
    every publisher offers it, so the subscription matches all of them."""
    from rclpy.qos import QoSDurabilityPolicy, QoSPresetProfiles, QoSReliabilityPolicy

    # A copy: the preset is rclpy's module-wide qos_profile_sensor_data, which every plot
    # and meter of this process subscribes with.
    qos = copy.copy(QoSPresetProfiles.SENSOR_DATA.value)
    pubs = sess.node.get_publishers_info_by_topic(topic)
    if pubs and all(p.qos_profile.reliability == QoSReliabilityPolicy.RELIABLE for p in pubs):
        qos.reliability = QoSReliabilityPolicy.RELIABLE
    if pubs and all(p.qos_profile.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL
                    for p in pubs):
        qos.durability = QoSDurabilityPolicy.TRANSIENT_LOCAL
    return qos


def _resolve_type(sess: Session, topic: str, msg_type: str | None, timeout: float) -> Any:
    if msg_type is not None:
        return message_class(msg_type)
    types = wait_until(lambda: _types_of(sess, topic), timeout)
    if types is None:
        raise GraphError(
            f'topic [{topic}] does not appear to be published yet: '
            'Could not determine the type for the passed topic',
            fix=unknown_topic_fix(topic, sess.node.get_topic_names_and_types()),
        )
    if len(types) > 1:
        raise GraphError(
            f"Cannot echo topic '{topic}', as it contains more than one type: "
            f"[{', '.join(types)}]"
        )
    return message_class(types[0])


def echo_stream(name: str, msg_type: str | None = None, *, timeout: float | None = None,
                type_timeout: float = LOOKUP_TIMEOUT, session: Session | None = None,
                raw: bool = False, with_info: bool = False, qos: Any = None,
                ) -> Iterator[Any]:
    """Messages from a topic as they arrive (the subscription lives while iterating).

    Stops `timeout` seconds after it began (None: never). A publisher that dies just means
    no more messages, never a hang past `timeout`. `raw` yields the serialized bytes;
    `with_info` yields (message, rmw message info dict) pairs (`echo --raw`/`-i`); `qos`
    replaces ros2cli's choice (sensor data, made reliable/transient as all offers are).
    """
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup

    sess = get_session(session)
    topic = absolute_name(name)
    cls = _resolve_type(sess, topic, msg_type, type_timeout)
    inbox: queue.Queue[Any] = queue.Queue()

    def with_message_info(msg: Any, info: Any) -> None:
        inbox.put((msg, info))

    callback: Any = with_message_info if with_info else inbox.put
    sub = sess.node.create_subscription(
        cls, topic, callback,
        _echo_qos(sess, topic) if qos is None else qos,
        callback_group=MutuallyExclusiveCallbackGroup(), event_callbacks=_without_qos_events(),
        raw=raw,
    )
    deadline = None if timeout is None else time.monotonic() + timeout
    try:
        while True:
            wait = None if deadline is None else deadline - time.monotonic()
            if wait is not None and wait <= 0:
                return
            try:
                # Short slices keep a kernel interrupt (KeyboardInterrupt) responsive.
                msg = inbox.get(timeout=0.1 if wait is None else min(wait, 0.1))
            except queue.Empty:
                continue
            yield msg
    finally:
        sess.node.destroy_subscription(sub)


def echo(topic: str, count: int = 1, timeout: float = 5.0, field: str | None = None,
         msg_type: str | None = None, session: Session | None = None) -> list[Any]:
    """The next `count` messages on `topic` (or the values of `field`, e.g. 'linear.x').

    GraphError if fewer than `count` arrive within `timeout` seconds.
    """
    got: list[Any] = []
    for msg in echo_stream(topic, msg_type, timeout=timeout, session=session):
        got.append(field_value(msg, field) if field else msg)
        if len(got) >= count:
            return got
    name = absolute_name(topic)
    raise GraphError(
        f'{len(got)} of {count} message(s) on {name} within {timeout:g} s',
        fix=f'is anything publishing? `robot-lab topic info -v {name}` shows the publishers',
    )


# The fewest intervals `topic_hz(enough=...)` ends on: the mean of fewer swings with one
# late message.
ENOUGH_INTERVALS = 5


@dataclass
class HzStats:
    """ros2 topic hz's numbers: rate (Hz) and min/max/std dev of the intervals (s)."""

    rate: float
    min: float
    max: float
    std_dev: float
    window: int

    def __str__(self) -> str:
        return (f'average rate: {self.rate:.3f}\n\tmin: {self.min:.3f}s max: {self.max:.3f}s '
                f'std dev: {self.std_dev:.5f}s window: {self.window}')


class RateMeter:
    """Arrival intervals of the last `window` messages, with ros2 topic hz's statistics."""

    def __init__(self, window: int = DEFAULT_WINDOW) -> None:
        self._lock = threading.Lock()
        self._intervals: deque[int] = deque(maxlen=window)
        self._last: int | None = None
        self.count = 0

    def tick(self, _msg: Any = None, now_ns: int | None = None) -> None:
        now = time.monotonic_ns() if now_ns is None else now_ns
        with self._lock:
            if self._last is not None:
                self._intervals.append(now - self._last)
            self._last = now
            self.count += 1

    def stats(self) -> HzStats | None:
        with self._lock:
            times = list(self._intervals)
        if not times:
            return None
        n = len(times)
        mean = sum(times) / n
        std = math.sqrt(sum((t - mean) ** 2 for t in times) / n)
        return HzStats(
            rate=1e9 / mean if mean > 0 else 0.0,
            min=min(times) * 1e-9,
            max=max(times) * 1e-9,
            std_dev=std * 1e-9,
            window=n,
        )


class RateSubscription:
    """A RateMeter fed by a subscription of the session (close() ends it)."""

    def __init__(self, sess: Session, topic: str, cls: Any, window: int) -> None:
        from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
        from rclpy.qos import qos_profile_sensor_data

        self.meter = RateMeter(window)
        self._sess = sess
        self._sub = sess.node.create_subscription(
            cls, topic, self.meter.tick, qos_profile_sensor_data,
            callback_group=MutuallyExclusiveCallbackGroup(), event_callbacks=_without_qos_events(),
        )

    def close(self) -> None:
        self._sess.node.destroy_subscription(self._sub)


def rate_subscription(name: str, window: int = DEFAULT_WINDOW, type_timeout: float = LOOKUP_TIMEOUT,
                      session: Session | None = None) -> RateSubscription:
    sess = get_session(session)
    topic = absolute_name(name)
    return RateSubscription(sess, topic, _resolve_type(sess, topic, None, type_timeout), window)


def topic_hz(topic: str, window: int = DEFAULT_WINDOW, duration: float = 5.0,
             session: Session | None = None, enough: float | None = None) -> HzStats:
    """Measure `topic`'s rate for `duration` seconds (ros2 topic hz's definitions), or
    only until the intervals measured span `enough` seconds (at least ENOUGH_INTERVALS of
    them): a check needs a rate, not the whole duration.

    GraphError when fewer than two messages arrive (no interval to measure).
    """
    meter = rate_subscription(topic, window, session=session)
    try:
        end = time.monotonic() + duration
        while time.monotonic() < end:
            if enough is not None and (stats := meter.meter.stats()) is not None \
                    and stats.window >= ENOUGH_INTERVALS and stats.window >= enough * stats.rate:
                break
            time.sleep(min(0.05, max(0.0, end - time.monotonic())))
    finally:
        meter.close()
    stats = meter.meter.stats()
    if stats is None:
        name = absolute_name(topic)
        raise GraphError(
            f'fewer than 2 messages on {name} in {duration:g} s: no rate to report',
            fix=f'is anything publishing? `robot-lab topic info -v {name}`',
        )
    return stats


_PUBLISHERS: weakref.WeakKeyDictionary[Session, dict[tuple[str, str, str], Publisher]] = (
    weakref.WeakKeyDictionary()
)


def qos_profile(profile: str = 'default', *, reliability: str | None = None,
                durability: str | None = None, depth: int | None = None,
                history: str | None = None, liveliness: str | None = None,
                lease_seconds: float | None = None) -> QoSProfile:
    """An rclpy QoSProfile from ros2cli's short keys (`--qos-profile sensor_data
    --qos-reliability reliable --qos-depth 5`), by ros2topic's rules: overrides replace the
    preset's policies; a transient-local profile of depth 0 gets depth 1."""
    from rclpy.duration import Duration
    from rclpy.qos import (
        QoSDurabilityPolicy,
        QoSHistoryPolicy,
        QoSLivelinessPolicy,
        QoSPresetProfiles,
        QoSReliabilityPolicy,
    )

    def lookup(kind: Any, key: str, what: str) -> Any:
        try:
            return kind.get_from_short_key(key)
        except (KeyError, AttributeError):
            raise GraphError(
                f"unknown QoS {what} '{key}'",
                fix=f'one of: {", ".join(kind.short_keys())}',
            ) from None

    qos: QoSProfile = copy.copy(lookup(QoSPresetProfiles, profile, 'profile'))  # not shared
    if history:
        qos.history = lookup(QoSHistoryPolicy, history, 'history')
    if durability:
        qos.durability = lookup(QoSDurabilityPolicy, durability, 'durability')
    if reliability:
        qos.reliability = lookup(QoSReliabilityPolicy, reliability, 'reliability')
    if liveliness:
        qos.liveliness = lookup(QoSLivelinessPolicy, liveliness, 'liveliness')
    if lease_seconds and lease_seconds >= 0:
        qos.liveliness_lease_duration = Duration(seconds=lease_seconds)
    if depth and depth >= 0:
        qos.depth = depth
    elif qos.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL and qos.depth == 0:
        qos.depth = 1
    return qos


def open_publisher(name: str, msg_type: str, session: Session | None = None,
                   qos: QoSProfile | None = None) -> Publisher:
    """The session's publisher for (topic, type, QoS), made once and kept (default QoS:
    reliable, volatile, depth 10).

    Keeping it means repeated publishes need no new discovery and nothing in flight is lost.
    """
    sess = get_session(session)
    topic = absolute_name(name)
    cls = message_class(msg_type)
    key = (topic, type_name(cls), '' if qos is None else repr(qos))
    cache = _PUBLISHERS.setdefault(sess, {})
    if key not in cache:
        cache[key] = sess.node.create_publisher(cls, topic, 10 if qos is None else qos)
    return cache[key]


def wait_for_subscribers(publisher: Publisher, count: int = 1,
                         timeout: float | None = 2.0) -> bool:
    """True once `count` subscriptions match `publisher` (False when `timeout` passes)."""
    deadline = None if timeout is None else time.monotonic() + timeout
    while publisher.get_subscription_count() < count:
        if deadline is not None and time.monotonic() >= deadline:
            return False
        time.sleep(0.02)
    return True


def publish(topic: str, msg_type: str, values: str | Mapping[str, Any] | Any = None,
            rate: float | None = None, times: int = 1, wait_for_subscriber: float = 1.0,
            session: Session | None = None) -> int:
    """Publish a message `times` times at `rate` Hz (default 1 Hz); returns how many.

    `values` is YAML text (`'{data: 22.5}'`, as `ros2 topic pub` takes), a dict, or a
    message. It first waits up to `wait_for_subscriber` s for a subscription to match, so a
    single message is not sent to no one.
    """
    cls = message_class(msg_type)
    if isinstance(values, cls):
        msg, restamp = values, None
    else:
        msg, restamp = stamped_message_from_yaml(cls, values)
    pub = open_publisher(topic, msg_type, session=session)
    if wait_for_subscriber > 0:
        wait_for_subscribers(pub, 1, wait_for_subscriber)
    period = 1.0 / (rate if rate else 1.0)
    start = time.monotonic()
    for i in range(times):
        if i:
            # Pace by the schedule (message i at start + i*period), not by sleeps that add up.
            delay = start + i * period - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        if restamp is not None:
            restamp()  # `header: auto`, `stamp: now`: the time of this publish
        pub.publish(msg)
    return times
