"""Playing a bag back onto live topics, as `ros2 bag play` does: same bytes, same timing.

The recorded CDR bytes are published unchanged (rclpy publishes raw bytes), at the
recorded receive-time gaps divided by `rate`. A virtual bag clock (anchored at the last
start/resume/rate change, robot_lab.bag.timeline) makes pause, resume and rate changes
exact. Before the first message the player waits, bounded, until its publishers have
matched the subscribers the graph already shows, so a listener that is running does not
miss the first messages; reliable topics are paced by acknowledgements
(robot_lab.bag.delivery). This module owns the options, the publishers and the thread.
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
from robot_lab.bag.delivery import flush_publishers, room_in_history, wait_for_matches
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
from robot_lab.bag.timeline import Timeline
from robot_lab.errors import BagError, GraphError

if TYPE_CHECKING:
    from rclpy.publisher import Publisher
    from rclpy.qos import QoSProfile
    from rosbags.interfaces import Connection

__all__ = ['Player', 'play']

NODE_NAME = 'rosbag2_player'


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
        self._timeline = Timeline(float(rate), bool(start_paused), self.log)
        self._cond = self._timeline.cond  # guards the timeline and the playing state
        self._done = threading.Event()
        self._thread: threading.Thread | None = None
        self._node: Any = None
        self._publishers: dict[str, Publisher] = {}
        self._connections: list[Connection] = []
        self.start_ns = 0
        self.end_ns = 0
        self.total = 0
        self._position_ns = 0
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
        return self._timeline.rate

    @property
    def paused(self) -> bool:
        return self._timeline.paused

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
            return min(self._timeline.now(), self.end_ns)

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
        self._timeline.pause()

    def resume(self) -> None:
        self._timeline.resume()

    def toggle_paused(self) -> None:
        if self._timeline.paused:
            self.resume()
        else:
            self.pause()

    def request_next(self) -> bool:
        """While paused, queue the next message to be published as soon as playback can
        (what the CURSOR_RIGHT key does: it never blocks); False when not paused."""
        return self._timeline.request_next()

    def play_next(self, timeout: float = 5.0) -> bool:
        """While paused, publish the next message now (rosbag2's play_next); True once out."""
        timeline = self._timeline
        with self._cond:
            before = self.played
            if not self.request_next():
                return False
            over = self._cond.wait_for(
                lambda: self.played > before or timeline.stopped or self._done.is_set(),
                timeout)
            if self.played == before:  # nothing left to play, or stopped: take the step back
                timeline.steps = max(0, timeline.steps - 1)
            return bool(over) and self.played > before

    def set_rate(self, rate: float) -> bool:
        return self._timeline.set_rate(rate)

    def stop(self, timeout: float = 10.0) -> None:
        """Stop playing now (publishers are destroyed; the bag is untouched)."""
        with self._cond:
            if (not self._timeline.stopped and self._thread is not None
                    and not self._done.is_set()):
                self.log('INFO', 'Stopping playback.')
            self._timeline.stopped = True
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
    def _stopped(self) -> bool:
        return self._timeline.stopped

    def _run(self) -> None:
        try:
            self.log('INFO', f'Playback until timestamp: {self.until_ns}')
            wait_for_matches(self._session, self._node, self._publishers.values(),
                             self._senders.values(), self._stopped, self._cond)
            first = self.start_ns + int(self.start_offset * 1e9)
            while not self._stopped():
                with self._cond:
                    if self.delay > 0 and self._cond.wait_for(self._stopped, self.delay):
                        break  # stopped during the delay
                if not self._play_once(first) or not self.loop:
                    break
            if self._clock is not None:
                self._clock.stop()  # the bag time ends with the bag
            flush_publishers(self._publishers.values(), self._stopped)
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
            self._timeline.start_at(first)
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
                how = self._timeline.wait_until(stamp)
                if how is None:
                    return False
                if self._clock is not None:
                    self._clock.before_message(conn.topic, stamp)
                sender = self._senders.get(conn.topic)
                if sender is None:
                    publisher = self._publishers[conn.topic]
                    if not room_in_history(publisher, conn.topic, self._unacked, self._stopped):
                        return False  # stopped while a subscriber caught up
                    publisher.publish(bytes(data))
                elif not sender.send(bytes(data)):
                    self._position_ns = stamp  # a response, or a request it could not send
                    if how == 'step':
                        with self._cond:
                            self._timeline.steps += 1  # play_next goes on to a message it can send
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
