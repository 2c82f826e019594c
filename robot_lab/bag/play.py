"""Playing a bag back onto live topics, as `ros2 bag play` does: same bytes, same timing.

The recorded CDR bytes are published unchanged (rclpy publishes raw bytes), at the
recorded receive-time gaps divided by `rate`. A virtual bag clock (anchored at the last
start/resume/rate change) makes pause, resume and rate changes exact. Before the first
message the player waits, bounded, until its publishers have matched the subscribers the
graph already shows, so a listener that is running does not miss the first messages.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

from robot_lab.bag.clock import ClockPublisher
from robot_lab.bag.console import log_line
from robot_lab.bag.qos import deep_history, load_overrides, publisher_qos
from robot_lab.bag.read import bag_messages, message_class_for, open_bag
from robot_lab.bag.selection import Selection
from robot_lab.bag.services import (
    REQUEST_SOURCES,
    RequestSource,
    ServiceRequestSender,
    is_service_event,
    service_name,
)
from robot_lab.errors import BagError, GraphError

if TYPE_CHECKING:
    from rclpy.publisher import Publisher
    from rclpy.qos import QoSProfile
    from rosbags.interfaces import Connection

__all__ = ['Player', 'play']

NODE_NAME = 'rosbag2_player'
DISCOVERY_WINDOW = 0.6  # one lease announcement of the kit's Fast DDS profile, and a bit
MATCH_TIMEOUT = 2.0  # longest wait for already-known subscribers to match
# KEEP_ALL publishers: how many messages may wait for acknowledgement at once.
ACK_WINDOW = 100
ACK_POLL = 0.1  # s between looks at `stop()` while a subscriber catches up
FLUSH_TIMEOUT = 30.0  # longest wait at the end for subscribers to acknowledge the rest


class Player:
    """A playback in progress: `progress`, `played`, `pause()`/`resume()`, `wait()`, `stop()`."""

    def __init__(
        self,
        bag: str | Path,
        *,
        rate: float = 1.0,
        loop: bool = False,
        topics: Iterable[str] | None = None,
        start_offset: float = 0.0,
        delay: float = 0.0,
        domain_id: int | None = None,
        log: Callable[[str], None] | None = None,
        node_name: str = NODE_NAME,
        qos_overrides: Mapping[str, QoSProfile] | str | Path | None = None,
        services: Iterable[str] | None = None,
        publish_service_requests: bool = False,
        service_requests_source: RequestSource = 'service_introspection',
        start_paused: bool = False,
        exclude_topics: Iterable[str] = (),
        exclude_services: Iterable[str] = (),
        regex: str = '',
        exclude_regex: str = '',
        remap: Mapping[str, str] | Iterable[str] | None = None,
        clock: float = 0.0,
        clock_topics: Iterable[str] = (),
        clock_topics_all: bool = False,
        playback_duration: float = -1.0,
        playback_until: int = -1,
    ) -> None:
        if rate <= 0:
            raise BagError(f'{rate} is not in the valid range (> 0.0)', fix='e.g. --rate 2')
        if start_offset < 0:
            raise BagError(
                f'Value {start_offset} is less than zero.', fix='--start-offset 0 or more'
            )
        self.bag = Path(bag)
        self._rate = float(rate)
        self.loop = loop
        # rosbag2 filters topics and services apart: `--topics` leaves services alone
        self.selection = Selection.of(topics, services, exclude_topics, exclude_services,
                                      regex, exclude_regex)
        # rosbag2's --remap: the player node's own remapping rules (`old:=new`)
        self.remap = ([f'{k}:={v}' for k, v in remap.items()] if isinstance(remap, Mapping)
                      else list(remap or ()))
        for rule in self.remap:
            if ':=' not in rule:
                raise BagError(f"Invalid remap rule '{rule}'", fix='write it old:=new, '
                               'e.g. --remap /sensor/temperature:=/replayed/temperature')
        if clock < 0:
            raise BagError(f'Value {clock} is less than zero.', fix='--clock 40 (Hz)')
        self.clock_hz = float(clock)
        self.clock_topics = list(clock_topics)
        self.clock_topics_all = clock_topics_all
        self._clock: ClockPublisher | None = None
        self.playback_duration = float(playback_duration)  # s; negative: to the end
        self.playback_until = int(playback_until)  # ns since the epoch; negative: unset
        self.until_ns = -1  # rosbag2's play_until_timestamp, set when the bag is opened
        if service_requests_source not in REQUEST_SOURCES:
            raise BagError(f'Unknown service requests source {service_requests_source!r}',
                           fix='use ' + ' or '.join(REQUEST_SOURCES))
        self.publish_service_requests = publish_service_requests
        self.service_requests_source: RequestSource = service_requests_source
        self._senders: dict[str, ServiceRequestSender] = {}  # event topic -> its client
        if delay < 0:
            raise BagError(f'Value {delay} is less than zero.', fix='--delay 0 or more')
        self.start_offset = start_offset
        # {topic: rclpy QoSProfile}, or the path of a `--qos-profile-overrides-path` file
        self.qos_overrides: dict[str, QoSProfile] = (
            load_overrides(qos_overrides) if isinstance(qos_overrides, (str, Path))
            else dict(qos_overrides or {})
        )
        self.qos: dict[str, QoSProfile] = {}  # topic -> the profile its publisher offers
        self._unacked: dict[str, int] = {}  # reliable topic -> sent since all were acked
        self.delay = float(delay)  # seconds before play, each loop (rosbag2's --delay)
        self.domain_id = domain_id
        self.node_name = node_name
        self._log_fn = log
        self.log_lines: list[str] = []
        self.played = 0
        self.counts: dict[str, int] = {}
        self.error: BaseException | None = None
        self._cond = threading.Condition()
        self._paused = bool(start_paused)  # rosbag2's -p/--start-paused
        self._steps = 0  # play_next() calls the playing thread has not served yet
        self._stop = False
        self._done = threading.Event()
        self._thread: threading.Thread | None = None
        self._node: Any = None
        self._publishers: dict[str, Publisher] = {}
        self._connections: list[Connection] = []
        self.start_ns = 0
        self.end_ns = 0
        self.total = 0
        self._position_ns = 0
        self._anchor_wall = 0.0
        self._anchor_bag = 0
        self.published: list[tuple[str, int, float]] = []  # (topic, bag ns, wall monotonic)
        self.keep_timing = False

    # ---------------------------------------------------------------- state
    def log(self, level: str, text: str) -> None:
        line = log_line(level, self.node_name, text)
        self.log_lines.append(line)
        if self._log_fn is not None:
            self._log_fn(line)

    @property
    def rate(self) -> float:
        return self._rate

    @property
    def paused(self) -> bool:
        return self._paused

    @property
    def running(self) -> bool:
        return self._thread is not None and not self._done.is_set()

    @property
    def finished(self) -> bool:
        return self._done.is_set()

    @property
    def progress(self) -> float:
        """0.0 … 1.0: how far through the bag's time span playback is."""
        span = self.end_ns - self.start_ns
        if span <= 0:
            return 1.0 if self.played else 0.0
        return min(1.0, max(0.0, (self._position_ns - self.start_ns) / span))

    @property
    def position(self) -> float:
        """Seconds of bag time played so far."""
        return max(0, self._position_ns - self.start_ns) / 1e9

    # ---------------------------------------------------------------- control
    def start(self) -> Player:
        """Check the bag, create the publishers and start playing (returns at once)."""
        if self._thread is None:
            self.open()
            self._thread = threading.Thread(target=self._run, name='robot_lab-bag-player',
                                            daemon=True)
            self._thread.start()
        return self

    def open(self) -> Player:
        """Check the bag and create the publishers, not playing yet (`start()` plays)."""
        if self._node is not None:
            return self
        import rclpy

        from robot_lab.rclpy_session import session

        with open_bag(self.bag) as reader:
            conns = list(reader.connections)
            self.start_ns = int(reader.start_time) if reader.message_count else 0
            self.end_ns = max(self.start_ns, int(reader.end_time) - 1)
        wanted = [c for c in conns if self.selection.allows(c.topic, c.msgtype)]
        for kind, only in (('Topic', self.selection.topics),
                           ('Service', self.selection.services)):
            for name in sorted(set(only or ()) - {c.topic for c in conns}):
                shown = name if kind == 'Topic' else service_name(name)
                self.log('WARN', f"{kind} '{shown}' is not in the bag; nothing to play for it")
        sess = session(self.domain_id)
        self._session = sess
        self._node = rclpy.create_node(
            self.node_name, context=sess.context, start_parameter_services=False,
            enable_rosout=False,
            cli_args=['--ros-args', *[a for r in self.remap for a in ('-r', r)]]
            if self.remap else None,
        )
        self.until_ns = self._until(self.start_ns + int(self.start_offset * 1e9))
        if self.until_ns >= 0:
            self.end_ns = max(self.start_ns, min(self.end_ns, self.until_ns))
        if self.clock_hz > 0 or self.clock_topics or self.clock_topics_all:
            self._clock = ClockPublisher(self._node, self._clock_now, self.clock_hz,
                                         self.clock_topics, self.clock_topics_all)
        for conn in wanted:
            if self.publish_service_requests and is_service_event(conn.topic, conn.msgtype):
                self._add_sender(conn)
                continue
            try:
                cls = message_class_for(conn.msgtype, self.bag, conn.topic)
            except BagError as exc:
                self.log('WARN', f"Ignoring a topic '{conn.topic}', reason: {exc}")
                continue
            if conn.topic not in self._publishers:
                qos = publisher_qos(
                    conn.topic, getattr(conn.ext, 'offered_qos_profiles', None) or [],
                    self.qos_overrides, self.log,
                )
                self.qos[conn.topic] = qos
                history = qos if conn.topic in self.qos_overrides else deep_history(
                    qos, sum(int(c.msgcount) for c in wanted if c.topic == conn.topic))
                self._publishers[conn.topic] = self._node.create_publisher(
                    cls, conn.topic, history
                )
                self.counts[conn.topic] = 0
            self._connections.append(conn)
        self.total = sum(int(c.msgcount) for c in self._connections)
        if self._senders:  # the clients' responses need spinning
            sess.add_node(self._node)
        return self

    def _until(self, starting: int) -> int:
        """rosbag2's play_until_timestamp: the later of start + duration and `until`."""
        if self.playback_duration < 0 and self.playback_until < 0:
            return -1
        by_duration = (0 if self.playback_duration == 0
                       else starting + int(self.playback_duration * 1e9))
        return max(by_duration, self.playback_until)

    def _clock_now(self) -> int:
        """The bag time for /clock: it runs with playback and stops at the bag's end."""
        with self._cond:
            return min(self._virtual_now(), self.end_ns)

    def _add_sender(self, conn: Connection) -> None:
        if conn.topic in self._senders:
            self._connections.append(conn)
            return
        try:
            sender = ServiceRequestSender(self._node, conn.topic, conn.msgtype,
                                          self.service_requests_source, self.log)
        except GraphError as exc:
            self.log('WARN', f"Ignoring a service '{service_name(conn.topic)}', "
                              f'reason: {exc}')
            return
        self._senders[conn.topic] = sender
        self.counts[conn.topic] = 0
        self._connections.append(conn)

    def pause(self) -> None:
        with self._cond:
            if not self._paused:
                self._anchor_bag = self._virtual_now()
                self._paused = True
                self.log('INFO', 'Pausing play.')
            self._cond.notify_all()

    def resume(self) -> None:
        with self._cond:
            if self._paused:
                self._anchor_wall = time.monotonic()
                self._paused = False
                self.log('INFO', 'Resuming play.')
            self._cond.notify_all()

    def toggle_paused(self) -> None:
        if self._paused:
            self.resume()
        else:
            self.pause()

    def request_next(self) -> bool:
        """While paused, queue the next message to be published as soon as playback can
        (what the CURSOR_RIGHT key does: it never blocks); False when not paused."""
        with self._cond:
            if not self._paused:
                self.log('WARN', 'Called play next, but not in paused state.')
                return False
            self._steps += 1
            self._cond.notify_all()
            return True

    def play_next(self, timeout: float = 5.0) -> bool:
        """While paused, publish the next message now (rosbag2's play_next); True once out."""
        with self._cond:
            before = self.played
            if not self.request_next():
                return False
            over = self._cond.wait_for(
                lambda: self.played > before or self._stop or self._done.is_set(), timeout)
            if self.played == before:  # nothing left to play, or stopped: take the step back
                self._steps = max(0, self._steps - 1)
            return bool(over) and self.played > before

    def set_rate(self, rate: float) -> bool:
        if rate <= 0:
            self.log('WARN', f'Failed to set rate to invalid value {rate}')
            return False
        with self._cond:
            self._anchor_bag = self._virtual_now()
            self._anchor_wall = time.monotonic()
            self._rate = float(rate)
            self._cond.notify_all()
        self.log('INFO', f'Set rate to {rate:g}')
        return True

    def stop(self, timeout: float = 10.0) -> None:
        """Stop playing now (publishers are destroyed; the bag is untouched)."""
        with self._cond:
            if not self._stop and self._thread is not None and not self._done.is_set():
                self.log('INFO', 'Stopping playback.')
            self._stop = True
            self._cond.notify_all()
        if self._thread is not None:
            self._thread.join(timeout)
        elif self._node is not None and not self._done.is_set():
            self._close()  # opened, never started

    def wait(self, timeout: float | None = None) -> bool:
        """Block until playback ends (never, with loop=True, unless stopped)."""
        finished = self._done.wait(timeout)
        if finished and self.error is not None:
            raise BagError(f"Playback of '{self.bag}' failed: {self.error}") from None
        return finished

    def __enter__(self) -> Player:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()

    # ---------------------------------------------------------------- playing
    def _virtual_now(self) -> int:
        if self._paused:
            return self._anchor_bag
        return self._anchor_bag + int((time.monotonic() - self._anchor_wall) * self._rate * 1e9)

    def _wait_until(self, stamp: int) -> str | None:
        """Sleep until bag time `stamp` is due ('due'), or a play_next() call releases it
        while paused ('step'); None if stopped meanwhile."""
        with self._cond:
            while not self._stop:
                if self._paused:
                    if self._steps:
                        self._steps -= 1
                        self._anchor_bag = max(self._anchor_bag, stamp)  # the clock jumps
                        return 'step'
                    self._cond.wait()
                    continue
                remaining = (stamp - self._virtual_now()) / 1e9 / self._rate
                if remaining <= 0:
                    return 'due'
                self._cond.wait(remaining)
            return None

    def _wait_for_matches(self) -> None:
        """Give subscribers the graph already knows the chance to match before message 1."""
        from robot_lab.graph.discovery import host_participants_seen

        sess = self._session
        # Every participant on the host seen, where the host's sockets can be counted: a
        # fixed window let a young player publish before it knew a loaded host's listener
        # (CI: the first 26 messages lost at --rate 4).
        everyone = host_participants_seen(sess)
        deadline = time.monotonic() + MATCH_TIMEOUT
        while not self._stop and time.monotonic() < deadline:
            seen = everyone()
            settled = seen if seen is not None else (
                time.monotonic() - getattr(sess, 'created', 0.0) >= DISCOVERY_WINDOW)
            matched = all(pub.get_subscription_count() >= self._matchable(pub)
                          for pub in self._publishers.values()) and self._services_ready()
            if settled and matched:
                return
            with self._cond:
                self._cond.wait(0.02)

    def _matchable(self, pub: Publisher) -> int:
        """How many subscriptions the graph shows on pub's topic that its QoS can match.

        A reliable subscriber never matches a best-effort offer (ROS's rule), so counting
        it would hold the first message for the whole MATCH_TIMEOUT.
        """
        from rclpy.qos import QoSCompatibility, qos_check_compatible

        return sum(
            qos_check_compatible(pub.qos_profile, info.qos_profile)[0]
            != QoSCompatibility.ERROR
            for info in self._node.get_subscriptions_info_by_topic(pub.topic_name))

    def _services_ready(self) -> bool:
        """Every recorded service the graph shows a server for is ready for requests."""
        if not self._senders:
            return True
        served = {name for name, _types in self._node.get_service_names_and_types()}
        return all(sender.client.service_is_ready() for sender in self._senders.values()
                   if sender.service in served)

    def _run(self) -> None:
        try:
            self.log('INFO', f'Playback until timestamp: {self.until_ns}')
            self._wait_for_matches()
            first = self.start_ns + int(self.start_offset * 1e9)
            while not self._stop:
                with self._cond:
                    if self.delay > 0 and self._cond.wait_for(lambda: self._stop, self.delay):
                        break  # stopped during the delay
                if not self._play_once(first) or not self.loop:
                    break
            if self._clock is not None:
                self._clock.stop()  # the bag time ends with the bag
            self._flush_publishers()
            for sender in self._senders.values():
                sender.wait_for_answers()
        except BaseException as exc:
            self.error = exc
        finally:
            self._close()

    def _close(self) -> None:
        try:
            if self._clock is not None:
                self._clock.destroy(self._node)
            if self._senders:
                self._session.remove_node(self._node)
            for pub in self._publishers.values():
                self._node.destroy_publisher(pub)
            self._node.destroy_node()
        except Exception:  # the context was shut down first (kernel exit): nothing to free
            pass
        self._done.set()
        with self._cond:
            self._cond.notify_all()  # a play_next() waiting for a message that never comes

    def _start_clock(self, first: int) -> None:
        """The bag's clock starts at `first` now, with the first message read: opening the
        bag and reading up to a start offset are not playback time. Anchored before them,
        a loaded CI host published the first 12 messages of `--rate 2` at once."""
        with self._cond:
            self._anchor_bag = first
            self._anchor_wall = time.monotonic()
            self._position_ns = first
        if self._clock is not None:
            self._clock.start()  # from the bag's first instant on (once)

    def _play_once(self, first: int) -> bool:
        with open_bag(self.bag) as reader:
            conns = [c for c in reader.connections
                     if c.topic in self._publishers or c.topic in self._senders]
            if not conns:
                return False
            # rosbag2 seeks only for a start offset: a message stamped before the metadata's
            # starting_time (rosbag2's own 5-file split test bag has them) still plays.
            since = first if self.start_offset > 0 else None
            anchored = False
            for conn, stamp, data in bag_messages(reader, conns, start=since):
                if not anchored:
                    self._start_clock(first)
                    anchored = True
                if self.until_ns == 0 or 0 < self.until_ns < stamp:
                    break  # --playback-duration / --playback-until reached
                how = self._wait_until(stamp)
                if how is None:
                    return False
                if self._clock is not None:
                    self._clock.before_message(conn.topic, stamp)
                sender = self._senders.get(conn.topic)
                if sender is None:
                    if not self._room_in_history(conn.topic):
                        return False  # stopped while a subscriber caught up
                    self._publishers[conn.topic].publish(bytes(data))
                elif not sender.send(bytes(data)):
                    self._position_ns = stamp  # a response, or a request it could not send
                    if how == 'step':
                        with self._cond:
                            self._steps += 1  # play_next goes on to a message it can send
                    continue
                self._position_ns = stamp
                self.played += 1
                self.counts[conn.topic] += 1
                if self.keep_timing:
                    self.published.append((conn.topic, stamp, time.monotonic()))
                if how == 'step':
                    with self._cond:
                        self._cond.notify_all()  # play_next() is waiting for this one
        self._position_ns = self.end_ns  # played to the end (of the selected topics)
        return True

    def _room_in_history(self, topic: str) -> bool:
        """Before a reliable volatile topic's next message: once its history holds `depth`
        messages not yet all acknowledged (the next would overwrite one a subscriber has
        not got), wait until its reliable subscribers have acknowledged them. A subscriber
        that falls behind makes the player fall behind the bag's clock instead of losing
        messages, as the recorded reliable QoS promises. (A transient-local topic keeps
        its recorded depth and is not paced: it promises late joiners the last `depth`.)
        False if stopped meanwhile."""
        from rclpy.duration import Duration
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

        publisher = self._publishers[topic]
        qos = publisher.qos_profile
        if (qos.reliability != ReliabilityPolicy.RELIABLE
                or qos.durability != DurabilityPolicy.VOLATILE):
            return True
        window = max(1, qos.depth if qos.history == HistoryPolicy.KEEP_LAST else ACK_WINDOW)
        sent = self._unacked.get(topic, 0)
        # Past half the window, look (without waiting) whether everything has been
        # acknowledged: the blocking wait below can take a writer heartbeat period.
        if sent >= window // 2 and publisher.wait_for_all_acked(Duration(seconds=0)):
            sent = 0
        if sent >= window:
            # A subscriber that is gone stops counting at its lease's end (2 s).
            while not publisher.wait_for_all_acked(Duration(seconds=ACK_POLL)):
                if self._stop:
                    return False
            sent = 0
        self._unacked[topic] = sent + 1
        return True

    def _flush_publishers(self) -> None:
        """Reliable subscribers get the last messages before the publishers go away (a
        subscriber that falls behind on a loaded host needs more than a moment)."""
        from rclpy.duration import Duration
        from rclpy.qos import ReliabilityPolicy

        deadline = time.monotonic() + FLUSH_TIMEOUT
        for pub in self._publishers.values():
            if pub.qos_profile.reliability != ReliabilityPolicy.RELIABLE:
                continue  # best effort: nothing is acknowledged
            while (not pub.wait_for_all_acked(Duration(seconds=ACK_POLL))
                   and not self._stop and time.monotonic() < deadline):
                pass


def play(bag: str | Path, **options: Any) -> Player:
    """Start playing a bag (folder or .mcap/.db3 file); returns the running Player.

    `player.wait()` blocks until it has played everything; `pause()`, `resume()`,
    `play_next()`, `set_rate()`, `stop()` control it; `progress` goes from 0.0 to 1.0.
    Options are `ros2 bag play`'s, as keywords (see `Player`): `rate`, `loop`, `topics`,
    `services`, `exclude_topics`, `exclude_services`, `regex`, `exclude_regex`, `remap`
    ({old: new}), `start_offset`, `delay`, `start_paused`, `playback_duration` (s),
    `playback_until` (ns), `clock` (Hz), `clock_topics`, `clock_topics_all`,
    `qos_overrides` ({topic: QoSProfile} or a `--qos-profile-overrides-path` file),
    `publish_service_requests`, `service_requests_source`, `domain_id`, `log`. Each topic
    offers the QoS its recorded publishers offered (rosbag2's rule, robot_lab.bag.qos).
    """
    return Player(bag, **options).start()
