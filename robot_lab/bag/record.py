"""Recording topics into a rosbag2 bag, as `ros2 bag record` does, without losing messages.

Why the design: a notebook's session executor is busy with plots and echoes, so the
recorder has its own node and its own single-threaded executor in a thread; callbacks
only take the raw CDR bytes and the DDS receive time (what rosbag2 Jazzy stores) and
queue them; a writer thread writes and flushes every half second, so a SIGKILL loses
little and a `stop()` (or Ctrl-C, or a kernel interrupt) drains the queue and closes a
complete bag. QoS follows rosbag2: reliable/transient-local only when every publisher
offers it; the queue is deep (KEEP_ALL when reliable) so a burst is not dropped.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime
import queue
import threading
import time
import weakref
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

from robot_lab.bag.console import log_line
from robot_lab.bag.qos import load_overrides
from robot_lab.bag.selection import RecordFilter
from robot_lab.bag.services import event_topic
from robot_lab.bag.writer import BagWriter, TopicSpec, qos_from_profile
from robot_lab.errors import BagError, GraphError

if TYPE_CHECKING:
    from rclpy.qos import QoSProfile
    from rclpy.subscription import Subscription
    from rclpy.topic_endpoint_info import TopicEndpointInfo

    from robot_lab.bag.info import BagInfo

__all__ = ['Recorder', 'default_bag_name', 'record']

NODE_NAME = 'rosbag2_recorder'
POLL_INTERVAL = 0.1  # rosbag2's default --polling-interval (100 ms)
FLUSH_PERIOD = 0.5  # at most this much recorded data is lost when the recorder is killed
NOT_FOUND_GRACE = 1.5  # discovery time before a missing topic is reported as missing
_STOP = object()
_ACTIVE: weakref.WeakSet[Recorder] = weakref.WeakSet()


@atexit.register
def _finish_recordings() -> None:
    """A kernel restart or interpreter exit closes running recordings (before ROS stops)."""
    for rec in list(_ACTIVE):
        with contextlib.suppress(Exception):  # exiting anyway; the bag can be reindexed
            rec.stop(timeout=10.0)


def default_bag_name(now: datetime.datetime | None = None) -> str:
    """`rosbag2_YYYY_MM_DD-HH_MM_SS`, the folder `ros2 bag record` makes by default."""
    return (now or datetime.datetime.now()).strftime('rosbag2_%Y_%m_%d-%H_%M_%S')


def type_hash_string(type_hash: Any) -> str:
    """rclpy's TypeHash -> `RIHS01_<hex>` as rosbag2 stores it ('' if unset)."""
    if type_hash is None or int(getattr(type_hash, 'version', 0)) != 1:
        return ''
    return 'RIHS01_' + bytes(type_hash.value).hex()


class Recorder:
    """A recording in progress: `start()`, live `counts`, `stop()`; or use `with`.

    topics: names to record (waits for each to appear); all_topics: every topic that has
    a publisher (like `ros2 bag record -a`, hidden topics excluded). The bag is finished
    (metadata.yaml written) when `stop()` returns, or when `duration` seconds or
    `max_messages` messages are reached.
    """

    def __init__(
        self,
        topics: Iterable[str] = (),
        *,
        all_topics: bool = False,
        output: str | Path | None = None,
        storage: str = 'mcap',
        duration: float | None = None,
        max_messages: int | None = None,
        domain_id: int | None = None,
        log: Callable[[str], None] | None = None,
        node_name: str = NODE_NAME,
        max_bag_size: int = 0,
        max_bag_duration: float = 0,
        services: Iterable[str] = (),
        all_services: bool = False,
        topic_types: Iterable[str] = (),
        regex: str = '',
        exclude_regex: str = '',
        exclude_topic_types: Iterable[str] = (),
        exclude_topics: Iterable[str] = (),
        exclude_services: Iterable[str] = (),
        include_hidden_topics: bool = False,
        include_unpublished_topics: bool = False,
        no_discovery: bool = False,
        polling_interval: float = POLL_INTERVAL,
        start_paused: bool = False,
        custom_data: Mapping[str, str] | None = None,
        qos_overrides: Mapping[str, QoSProfile] | str | Path | None = None,
    ) -> None:
        topics, services = list(topics), list(services)
        # rosbag2's record filter (robot_lab.bag.selection): lists, types, regexes, hidden
        self.filter = RecordFilter.of(
            topics, services, topic_types, all_topics, all_services, regex, exclude_regex,
            exclude_topic_types, exclude_topics, exclude_services, include_hidden_topics)
        if not topics and not services and not self.filter.open_ended:
            raise BagError(
                'Need to specify at least one option out of --all, --all-topics, '
                '--all-services, --services, --topics, --topic-types or --regex',
                fix='e.g. `robot-lab bag record /sensor/temperature` or `-a`',
            )
        names = [t if t.startswith('/') else '/' + t for t in topics]
        # rosbag2's --service NAME / --all-services: the services' introspection topics
        names += [event_topic(s) for s in services]
        hidden = set(self.filter.hidden_listed())
        self.topics = [t for t in dict.fromkeys(names) if t not in hidden]
        self.all_topics = all_topics
        self.all_services = all_services
        self.include_unpublished = include_unpublished_topics
        self.no_discovery = no_discovery  # look for topics once, at the start
        self.polling_interval = float(polling_interval)
        self._open_ended = self.filter.open_ended  # new topics may come at any time
        self._paused = bool(start_paused)  # paused, messages are taken and dropped
        self.custom_data = dict(custom_data or {})  # metadata.yaml's custom_data
        # {topic: rclpy QoSProfile}, or the path of a `--qos-profile-overrides-path` file
        self.qos_overrides: dict[str, QoSProfile] = (
            load_overrides(qos_overrides) if isinstance(qos_overrides, (str, Path))
            else dict(qos_overrides or {}))
        self.path = Path(output) if output else Path(default_bag_name())
        self.storage = storage
        self.duration = duration
        self.max_messages = max_messages
        self.max_bag_size = max_bag_size  # bytes per file before a split (0: one file)
        self.max_bag_duration = max_bag_duration  # seconds per file before a split
        self.domain_id = domain_id
        self.node_name = node_name
        self._log_fn = log
        self.log_lines: list[str] = []
        self.counts: dict[str, int] = {}
        self.types: dict[str, str] = {}
        self.received = 0
        self.error: BaseException | None = None
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._stop = threading.Event()
        self._done = threading.Event()
        self._started_at: float | None = None
        self._stopped_at: float | None = None
        self._writer: BagWriter | None = None
        self._subs: dict[str, Subscription] = {}
        self._warned: set[str] = set()
        self._spin_thread: threading.Thread | None = None
        self._write_thread: threading.Thread | None = None
        self._node: Any = None
        self._executor: Any = None

    # ---------------------------------------------------------------- state
    @property
    def running(self) -> bool:
        return self._started_at is not None and not self._done.is_set()

    @property
    def finished(self) -> bool:
        return self._done.is_set()

    @property
    def elapsed(self) -> float:
        """Seconds since start (frozen when the recording stopped)."""
        if self._started_at is None:
            return 0.0
        end = self._stopped_at if self._stopped_at is not None else time.monotonic()
        return end - self._started_at

    @property
    def total(self) -> int:
        return sum(self.counts.values())

    def log(self, level: str, text: str) -> None:
        line = log_line(level, self.node_name, text)
        self.log_lines.append(line)
        if self._log_fn is not None:
            self._log_fn(line)

    # ---------------------------------------------------------------- control
    def open(self) -> Recorder:
        """Create the bag (an existing folder is refused here), not recording yet."""
        if self._writer is None:
            self._writer = BagWriter(self.path, self.storage, max_bag_size=self.max_bag_size,
                                     max_bag_duration=self.max_bag_duration,
                                     custom_data=self.custom_data)
        return self

    def start(self) -> Recorder:
        """Open the bag and start discovering and recording topics (returns at once)."""
        if self._started_at is not None:
            return self
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        from robot_lab.rclpy_session import session

        self.open()
        assert self._writer is not None
        sess = session(self.domain_id)
        try:
            self._node = rclpy.create_node(
                self.node_name, context=sess.context, start_parameter_services=False,
                enable_rosout=False,
            )
            self._executor = SingleThreadedExecutor(context=sess.context)
            self._executor.add_node(self._node)
        except Exception:
            self._writer.close()
            raise
        self._started_at = time.monotonic()
        _ACTIVE.add(self)
        self.log('INFO', 'Listening for topics...')
        if self.filter.hidden_listed():
            self.log('WARN', 'Hidden topics are not recorded. Enable them with '
                              '--include-hidden-topics')
        self._write_thread = threading.Thread(
            target=self._write_loop, name='robot_lab-bag-writer', daemon=True
        )
        self._spin_thread = threading.Thread(
            target=self._spin_loop, name='robot_lab-bag-recorder', daemon=True
        )
        self._write_thread.start()
        self._spin_thread.start()
        if self._paused:
            self.log('INFO', 'Wait for recording: Press SPACE to start.')
        else:
            self.log('INFO', 'Recording...')
        return self

    @property
    def paused(self) -> bool:
        return self._paused

    def pause(self) -> None:
        """Stop writing messages (the recording stays open), as rosbag2's pause."""
        if not self._paused:
            self._paused = True
            self.log('INFO', 'Pausing recording.')

    def resume(self) -> None:
        if self._paused:
            self._paused = False
            self.log('INFO', 'Resuming recording.')

    def toggle_paused(self) -> None:
        if self._paused:
            self.resume()
        else:
            self.pause()

    def stop(self, timeout: float = 30.0) -> Path:
        """Stop recording, write what was received, close the bag; returns its folder."""
        if self._started_at is None:
            raise BagError('The recording was never started', fix='call start() first')
        self._stop.set()
        if not self._done.wait(timeout):
            raise BagError(
                f"Recorder did not finish writing '{self.path}' within {timeout:g} s",
                fix='check the disk (full? slow network folder?)',
            )
        if self.error is not None:
            raise BagError(
                f"Recording to '{self.path}' failed: {self.error}",
                fix='check that the folder is writable and the disk is not full',
            )
        return self.path

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the recording ends by itself (duration/max_messages) or is stopped."""
        return self._done.wait(timeout)

    def __enter__(self) -> Recorder:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()

    def info(self) -> BagInfo:
        """The finished bag's metadata."""
        from robot_lab.bag.info import bag_info

        return bag_info(self.path)

    # ---------------------------------------------------------------- threads
    def _limit_reached(self) -> bool:
        if self.duration is not None and self.elapsed >= self.duration:
            return True
        return self.max_messages is not None and self.received >= self.max_messages

    def _spin_loop(self) -> None:
        next_poll = 0.0
        try:
            while not self._stop.is_set() and not self._limit_reached():
                now = time.monotonic()
                if now >= next_poll and (self._open_ended or len(self._subs) < len(self.topics)):
                    self._discover()
                    # --no-discovery: only what is there at the start (never look again)
                    next_poll = float('inf') if self.no_discovery else now + self.polling_interval
                self._executor.spin_once(timeout_sec=0.05)
            self._drain_subscriptions()
        except BaseException as exc:
            self.error = exc
        finally:
            self._stopped_at = time.monotonic()
            self._teardown_node()
            self._queue.put(_STOP)

    def _drain_subscriptions(self) -> None:
        """Take what DDS already received before closing: stop must not drop messages."""
        if self.max_messages is not None and self.received >= self.max_messages:
            return
        quiet = 0
        deadline = time.monotonic() + 5.0
        while quiet < 3 and time.monotonic() < deadline:
            before = self.received
            self._executor.spin_once(timeout_sec=0.0)
            quiet = quiet + 1 if self.received == before else 0

    def _teardown_node(self) -> None:
        try:
            for sub in self._subs.values():
                self._node.destroy_subscription(sub)
            self._executor.remove_node(self._node)
            self._executor.shutdown(timeout_sec=1.0)
            self._node.destroy_node()
        except Exception:  # the context was shut down first (kernel exit): nothing to free
            pass
        missing = [t for t in self.topics if t not in self._subs]
        for topic in missing:
            self.log('WARN', f"Topic '{topic}' was never found: nothing recorded for it")

    def _write_loop(self) -> None:
        writer = self._writer
        assert writer is not None
        last_flush = time.monotonic()
        try:
            while True:
                try:
                    item = self._queue.get(timeout=0.1)
                except queue.Empty:
                    item = None
                if item is _STOP:
                    break
                if item is not None:
                    self._write_item(writer, item)
                    # Write the backlog in one go before checking the clock again.
                    for _ in range(10000):
                        try:
                            item = self._queue.get_nowait()
                        except queue.Empty:
                            break
                        if item is _STOP:
                            self._queue.put(_STOP)
                            break
                        self._write_item(writer, item)
                if time.monotonic() - last_flush >= FLUSH_PERIOD:
                    writer.flush()
                    last_flush = time.monotonic()
            while True:  # whatever arrived before the stop marker is already written
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    break
                if item is not _STOP:
                    self._write_item(writer, item)
        except BaseException as exc:
            self.error = exc
            self._stop.set()
        finally:
            try:
                writer.close()
                self.log('INFO', 'Recording stopped')
            except BaseException as exc:
                self.error = self.error or exc
            self._done.set()
            _ACTIVE.discard(self)

    @staticmethod
    def _write_item(writer: BagWriter, item: Any) -> None:
        if isinstance(item, TopicSpec):
            writer.add_topic(item)
            return
        topic, stamp, data = item
        writer.write(writer.connections[topic], stamp, data)

    # ---------------------------------------------------------------- discovery
    def _wanted(self, available: dict[str, list[str]]) -> list[str]:
        wanted = [t for t in self.topics
                  if t not in available or self.filter.takes(t, available[t][0])]
        wanted += [t for t in sorted(available)
                   if len(available[t]) == 1 and self.filter.takes(t, available[t][0])]
        return list(dict.fromkeys(wanted))

    def _discover(self) -> None:
        available = dict(self._node.get_topic_names_and_types())
        for topic in self._wanted(available):
            if topic in self._subs:
                continue
            publishers = (
                self._node.get_publishers_info_by_topic(topic) if topic in available else []
            )
            if not publishers and self.include_unpublished and topic in available:
                publishers = []  # --include-unpublished-topics: subscribe all the same
            elif not publishers:
                if (
                    not self._open_ended
                    and topic not in self._warned
                    and self.elapsed >= NOT_FOUND_GRACE
                ):
                    self._warned.add(topic)
                    self.log(
                        'WARN',
                        f"Topic '{topic}' not found... waiting for a publisher — fix: start "
                        'the node that publishes it (`robot-lab topic list` shows what exists)',
                    )
                continue
            self._subscribe(topic, available[topic][0], publishers)

    def _subscribe(self, topic: str, msgtype: str,
                   publishers: list[TopicEndpointInfo]) -> None:
        from rclpy.qos import (
            DurabilityPolicy,
            HistoryPolicy,
            QoSProfile,
            ReliabilityPolicy,
        )

        from robot_lab.messages import message_class

        try:
            cls = message_class(msgtype)
        except GraphError:
            if topic not in self._warned:
                self._warned.add(topic)
                self.log(
                    'WARN',
                    f"Topic '{topic}' has type '{msgtype}', unknown in this environment — "
                    f"fix: build and source the package '{msgtype.split('/')[0]}'",
                )
            return
        reliable = all(p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers)
        latched = all(
            p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers
        )
        qos = QoSProfile(
            history=HistoryPolicy.KEEP_ALL if reliable else HistoryPolicy.KEEP_LAST,
            depth=1000,
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        )
        if topic in self.qos_overrides:
            self.log('INFO', f'Overriding subscription profile for {topic}')
            qos = self.qos_overrides[topic]
        hashes = {type_hash_string(p.topic_type_hash) for p in publishers} - {''}
        spec = TopicSpec(
            name=topic,
            type=msgtype,
            offered_qos_profiles=[qos_from_profile(p.qos_profile) for p in publishers],
            type_description_hash=hashes.pop() if len(hashes) == 1 else '',
        )
        # The writer learns the topic before the first message can arrive (same queue).
        self._queue.put(spec)
        self.counts.setdefault(topic, 0)
        self.types[topic] = msgtype

        def accept(data: bytes, info: Any) -> bool:
            if self.max_messages is not None and self.received >= self.max_messages:
                return False
            if self._paused:
                return False
            stamp = info.get('received_timestamp') if isinstance(info, dict) else None
            self.received += 1
            self.counts[topic] += 1
            self._queue.put((topic, stamp or time.time_ns(), data))
            return True

        def on_message(data: bytes, info: Any) -> None:
            if accept(data, info) and self._batch_take:
                self._take_backlog(self._subs[topic], accept)

        self._subs[topic] = self._node.create_subscription(cls, topic, on_message, qos, raw=True)
        self.log('INFO', f"Subscribed to topic '{topic}'")
        if not self._open_ended and len(self._subs) == len(self.topics):
            self.log('INFO', 'All requested topics are subscribed. Stopping discovery...')


    _batch_take = True

    def _take_backlog(self, sub: Any, accept: Callable[[bytes, Any], bool]) -> None:
        """Take what else is already queued for `sub` in one go.

        The executor pays a whole wait-set round trip per message; taking the backlog
        here (what rclpy's executor does per message: `handle.take_message`) lets a
        burst be drained at the cost of one round trip.
        """
        try:
            for _ in range(256):
                with sub.handle:
                    taken = sub.handle.take_message(sub.msg_type, True)
                if taken is None or not accept(taken[0], taken[1]):
                    return
        except (AttributeError, TypeError):  # another rclpy: per-message callbacks only
            self._batch_take = False


def record(*topics: str, **options: Any) -> Recorder:
    """Start recording `topics` (or all) into a rosbag2 bag; returns the running Recorder.

    Use it as a handle (`rec = record('/sensor/temperature'); …; rec.stop()`) or as a
    context manager (`with record('/sensor/temperature', output='run1'): …`). With
    `duration`, `rec.wait()` returns when the recording has finished by itself.
    Options are `ros2 bag record`'s, as keywords (see `Recorder`): `all_topics`,
    `output`, `storage`, `duration`, `max_messages`, `max_bag_size` (bytes) /
    `max_bag_duration` (s) to split into <bag>_0, <bag>_1, …, `services`,
    `all_services`, `topic_types`, `regex`, `exclude_regex`, `exclude_topic_types`,
    `exclude_topics`, `exclude_services`, `include_hidden_topics`,
    `include_unpublished_topics`, `no_discovery`, `polling_interval` (s), `domain_id`, `log`.
    """
    return Recorder(topics, **options).start()
