"""`ros2 bag play`'s controls: `--start-paused`, play next, and the keyboard in a terminal
(SPACE pause/resume, CURSOR_RIGHT next message, CURSOR_UP/DOWN rate ± 0.1), as rosbag2.

The bag is written here: twenty std_msgs/Int32 (0 … 19) on /counter, 0.1 s apart, so the
order and the count of what a subscriber receives show what was played.
"""

from __future__ import annotations

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


@pytest.fixture(scope='module')
def counter_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    bag = tmp_path_factory.mktemp('controls') / 'counter'
    writer = BagWriter(bag, 'mcap')
    conn = writer.add_topic(TopicSpec('/counter', 'std_msgs/msg/Int32', []))
    for i in range(COUNT):  # CDR: little-endian header, then the int32
        writer.write(conn, 1_700_000_000_000_000_000 + i * 100_000_000,
                     bytes([0, 1, 0, 0]) + i.to_bytes(4, 'little'))
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

    from robot_lab.context import session

    got = Received()
    node = session().node
    sub = node.create_subscription(Int32, '/counter', got.take, 100)
    yield got
    node.destroy_subscription(sub)


def test_start_paused_then_play_next_then_resume(counter_bag: Path, received: Received) -> None:
    player = robot_lab.play(counter_bag, start_paused=True)
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
    again = robot_lab.play(counter_bag)
    try:
        assert not again.play_next()
        assert again.log_lines[-1].endswith('Called play next, but not in paused state.')
    finally:
        again.stop()


def test_keyboard_controls_in_a_terminal(counter_bag: Path, received: Received) -> None:
    keys, terminal = pty.openpty()
    play = Proc([str(BIN / 'ros2'), 'bag', 'play', '--start-paused', str(counter_bag)],
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
