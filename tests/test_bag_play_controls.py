"""`ros2 bag play`'s controls and options, as rosbag2: `--start-paused`, play next, the
keyboard in a terminal (SPACE pause/resume, CURSOR_RIGHT next message, CURSOR_UP/DOWN rate
± 0.1), the topic filters, `--remap`, `--playback-duration/-until` and `--clock`.

The bag is written here: twenty std_msgs/Int32 (0 … 19) on /counter, 0.1 s apart, and
(from 100) on /other between them, so the order and the count of what a subscriber
receives show what was played.
"""

from __future__ import annotations

import contextlib
import os
import pty
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, Proc

import robot_lab
from robot_lab.bag.writer import BagWriter, TopicSpec

COUNT = 20
START = 1_700_000_000_000_000_000  # the first message's receive time, ns
STEP = 100_000_000


@contextlib.contextmanager
def clock_listener(clocks: list[int]) -> Iterator[None]:
    """/clock's times (ns) appended to `clocks`, read best effort as rclpy's TimeSource."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    from robot_lab.rclpy_session import session

    node = session().node
    sub = node.create_subscription(
        Clock, '/clock', lambda m: clocks.append(m.clock.sec * 10**9 + m.clock.nanosec),
        QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT))
    try:
        yield
    finally:
        node.destroy_subscription(sub)


def _int32(value: int) -> bytes:
    return bytes([0, 1, 0, 0]) + value.to_bytes(4, 'little')  # CDR header, then the int32


@pytest.fixture(scope='module')
def counter_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    bag = tmp_path_factory.mktemp('controls') / 'counter'
    writer = BagWriter(bag, 'mcap')
    counter = writer.add_topic(TopicSpec('/counter', 'std_msgs/msg/Int32', []))
    other = writer.add_topic(TopicSpec('/other', 'std_msgs/msg/Int32', []))
    for i in range(COUNT):
        writer.write(counter, START + i * STEP, _int32(i))
        writer.write(other, START + i * STEP + STEP // 2, _int32(100 + i))
    writer.close()
    return bag


class Received:
    """What /counter delivered to this process's session, with a wait for the n-th."""

    def __init__(self) -> None:
        self.values: list[int] = []
        self._changed = threading.Condition()

    def take(self, msg: object) -> None:
        with self._changed:
            self.values.append(int(msg.data))  # type: ignore[attr-defined]
            self._changed.notify_all()

    def wait_for(self, count: int, timeout: float = 20.0) -> list[int]:
        with self._changed:
            self._changed.wait_for(lambda: len(self.values) >= count, timeout)
            return list(self.values)


@pytest.fixture
def received() -> Iterator[Received]:
    from std_msgs.msg import Int32

    from robot_lab.rclpy_session import session

    got = Received()
    node = session().node
    sub = node.create_subscription(Int32, '/counter', got.take, 100)
    yield got
    node.destroy_subscription(sub)


def test_start_paused_then_play_next_then_resume(counter_bag: Path, received: Received) -> None:
    player = robot_lab.play(counter_bag, start_paused=True, topics=['/counter'])
    try:
        assert player.paused
        for n in (1, 2, 3):
            assert player.play_next()
            assert received.wait_for(n) == list(range(n))
        assert player.played == 3 and player.paused
        player.resume()
        assert player.wait(30)
    finally:
        player.stop()
    assert received.wait_for(COUNT) == list(range(COUNT))  # nothing twice, nothing lost
    # while playing, play_next is refused with rosbag2's warning
    again = robot_lab.play(counter_bag, topics=['/counter'])
    try:
        assert not again.play_next()
        assert again.log_lines[-1].endswith('Called play next, but not in paused state.')
    finally:
        again.stop()


def test_keyboard_controls_in_a_terminal(counter_bag: Path, received: Received) -> None:
    keys, terminal = pty.openpty()
    play = Proc([str(BIN / 'ros2'), 'bag', 'play', '--start-paused', str(counter_bag),
                 '--topics', '/counter'],
                env=dict(os.environ), stdin=terminal)
    os.close(terminal)
    try:
        for line in ('Adding keyboard callbacks.', 'Press SPACE for Pause/Resume',
                     'Press CURSOR_RIGHT for Play Next Message',
                     'Press CURSOR_UP for Increase Rate 10%',
                     'Press CURSOR_DOWN for Decrease Rate 10%'):
            play.wait_for(line + '$', timeout=60)
        for n in (1, 2):
            os.write(keys, b'\x1b[C')  # CURSOR_RIGHT
            assert received.wait_for(n) == list(range(n)), play.output
        os.write(keys, b'\x1b[A\x1b[A')  # CURSOR_UP twice: 1.0 -> 1.2
        play.wait_for(r'Set rate to 1\.2$')
        os.write(keys, b'\x1b[B')  # CURSOR_DOWN: 1.1
        play.wait_for(r'Set rate to 1\.1$')
        os.write(keys, b' ')  # SPACE: resume
        play.wait_for('Resuming play.')
        assert received.wait_for(COUNT) == list(range(COUNT)), play.output
        assert play.popen.wait(30) == 0
        assert 'Traceback' not in play.output
    finally:
        play.stop()
        os.close(keys)


def test_without_a_terminal_the_keys_are_announced_and_ignored(counter_bag: Path) -> None:
    play = Proc([str(BIN / 'ros2'), 'bag', 'play', str(counter_bag)], env=dict(os.environ))
    try:
        assert play.popen.wait(60) == 0
    finally:
        play.stop()
    assert 'Press SPACE for Pause/Resume' in play.output
    assert 'stdin is not a terminal device. Keyboard handling disabled.' in play.output
    quiet = Proc([str(BIN / 'ros2'), 'bag', 'play', '--disable-keyboard-controls',
                  str(counter_bag)], env=dict(os.environ))
    try:
        assert quiet.popen.wait(60) == 0
    finally:
        quiet.stop()
    assert 'Press SPACE' not in quiet.output and 'Keyboard handling' not in quiet.output


def _counts(bag: Path, **options: object) -> dict[str, int]:
    player = robot_lab.play(bag, **options)
    try:
        assert player.wait(60)
    finally:
        player.stop()
    return {topic: n for topic, n in player.counts.items() if n}


def test_topic_filters_follow_rosbag2(counter_bag: Path) -> None:
    both = {'/counter': COUNT, '/other': COUNT}
    assert _counts(counter_bag, rate=20) == both
    assert _counts(counter_bag, rate=20, exclude_topics=['/other']) == {'/counter': COUNT}
    assert _counts(counter_bag, rate=20, regex='/oth.*') == {'/other': COUNT}
    assert _counts(counter_bag, rate=20, regex='/oth') == {}  # a whole-name match
    assert _counts(counter_bag, rate=20, exclude_regex='/c.*') == {'/other': COUNT}
    # a listed topic or a regex match plays
    assert _counts(counter_bag, rate=20, topics=['/counter'], regex='/oth.*') == both
    with pytest.raises(robot_lab.BagError, match='Invalid regular expression for --regex'):
        robot_lab.play(counter_bag, regex='(')


def test_playback_duration_and_until(counter_bag: Path) -> None:
    """Messages stamped after start + duration (or `until`) do not play; the later of the
    two bounds wins; 0 plays nothing."""
    assert _counts(counter_bag, rate=20, topics=['/counter'],
                   playback_duration=0.45) == {'/counter': 5}  # 0.0 ... 0.4 s
    assert _counts(counter_bag, rate=20, topics=['/counter'],
                   playback_until=START + 2 * STEP) == {'/counter': 3}
    assert _counts(counter_bag, rate=20, topics=['/counter'], playback_duration=0.45,
                   playback_until=START + 9 * STEP) == {'/counter': 10}
    assert _counts(counter_bag, rate=20, playback_duration=0) == {}


def test_remap_and_clock(counter_bag: Path, received: Received) -> None:
    """`--remap /other:=/counter` and `--clock-topics-all`: /counter gets both topics'
    messages, and /clock the bag time of each just before it."""
    clocks: list[int] = []
    with clock_listener(clocks):
        play = Proc([str(BIN / 'ros2'), 'bag', 'play', str(counter_bag),
                     '--remap', '/other:=/counter', '--clock-topics-all',
                     '--disable-keyboard-controls'], env=dict(os.environ))
        try:
            assert play.popen.wait(60) == 0, play.output
        finally:
            play.stop()
        assert sorted(received.wait_for(2 * COUNT)) == sorted(
            [*range(COUNT), *range(100, 100 + COUNT)])
    stamps = sorted({START + i * STEP for i in range(COUNT)}
                    | {START + i * STEP + STEP // 2 for i in range(COUNT)})
    # best effort, depth 1: a clock update may be lost, never invented or out of order
    assert set(clocks) <= set(stamps) and clocks == sorted(clocks)
    assert len(clocks) >= COUNT // 2, clocks


def test_clock_at_a_rate_follows_the_bag_time(counter_bag: Path) -> None:
    clocks: list[int] = []
    with clock_listener(clocks):
        player = robot_lab.play(counter_bag, clock=50, topics=['/counter'])
        assert player.wait(60)
    # 1.9 s of bag time at 50 Hz: about 95 updates, all within the bag, never backwards
    assert len(clocks) >= 40, len(clocks)
    assert clocks == sorted(clocks)
    assert clocks[0] >= START and clocks[-1] <= START + COUNT * STEP
