"""teleop_twist_keyboard as ros2/teleop_twist_keyboard 2.4.1 behaves, and the notebook pad.

The key table against upstream's documented keys (pure Python); the terminal program run
with `ros2 run` in a pty, its keys checked as the Twists a subscriber receives (speed
changes, strafing, stop, zero on CTRL-C); the notebook pad driven through its widget
model, as a browser drives it, publishing TwistStamped while held and zero on release.
"""

from __future__ import annotations

import os
import pty
import select
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from conftest import BIN

from robot_lab.keyboard_teleop.keys import BANNER, MOVES, SPEEDS, Drive, speed_line
from robot_lab.keyboard_teleop.terminal import NO_TERMINAL
from robot_lab.process import spawn


class Inbox:
    """Messages of `kind` on `topic`, received by the test's own session node."""

    def __init__(self, topic: str, kind: Any) -> None:
        from robot_lab.rclpy_session import session

        self.session = session()
        self.messages: list[Any] = []
        self.changed = threading.Condition()
        self.subscription = self.session.run_in_executor(
            lambda: self.session.node.create_subscription(kind, topic, self._take, 10))

    def _take(self, message: Any) -> None:
        with self.changed:
            self.messages.append(message)
            self.changed.notify_all()

    def wait(self, test: Callable[[list[Any]], bool], what: str,
             timeout: float = 20.0, poke: Callable[[], None] | None = None) -> list[Any]:
        """Until `test(messages)`; `poke()` (a key press) every half second meanwhile."""
        deadline = time.monotonic() + timeout
        with self.changed:
            while not test(self.messages):
                left = deadline - time.monotonic()
                assert left > 0, f'{what}: not within {timeout} s ({self.messages[-3:]})'
                if poke is not None:
                    self.changed.release()
                    try:
                        poke()
                    finally:
                        self.changed.acquire()
                self.changed.wait(min(left, 0.5))
            return list(self.messages)

    def close(self) -> None:
        self.session.run_in_executor(
            lambda: self.session.node.destroy_subscription(self.subscription))


ZERO = (0.0,) * 6


def parts(twist: Any) -> tuple[float, float, float, float, float, float]:
    return (twist.linear.x, twist.linear.y, twist.linear.z,
            twist.angular.x, twist.angular.y, twist.angular.z)


# -- the key table ----------------------------------------------------------------------

@pytest.mark.no_ros
def test_keys_are_upstreams() -> None:
    drive = Drive()
    expected = {  # key -> (linear x, y, z, angular z) at speed 0.5, turn 1.0
        'u': (0.5, 0, 0, 1), 'i': (0.5, 0, 0, 0), 'o': (0.5, 0, 0, -1),
        'j': (0, 0, 0, 1), 'l': (0, 0, 0, -1),
        'm': (-0.5, 0, 0, -1), ',': (-0.5, 0, 0, 0), '.': (-0.5, 0, 0, 1),
        'U': (0.5, 0.5, 0, 0), 'I': (0.5, 0, 0, 0), 'O': (0.5, -0.5, 0, 0),
        'J': (0, 0.5, 0, 0), 'L': (0, -0.5, 0, 0),
        'M': (-0.5, 0.5, 0, 0), '<': (-0.5, 0, 0, 0), '>': (-0.5, -0.5, 0, 0),
        't': (0, 0, 0.5, 0), 'b': (0, 0, -0.5, 0),
    }
    assert set(MOVES) == set(expected)
    for key, velocity in expected.items():
        assert drive.press(key) is False
        assert drive.velocity == velocity, key
    for other in 'kKa1 \x1b':  # anything else: stop
        drive.press('i')
        drive.press(other)
        assert drive.velocity == (0, 0, 0, 0), repr(other)
    # the speed keys scale and keep the direction
    drive.press('u')
    factors = {'q': (1.1, 1.1), 'z': (0.9, 0.9), 'w': (1.1, 1), 'x': (0.9, 1),
               'e': (1, 1.1), 'c': (1, 0.9)}
    assert factors == SPEEDS
    for key, (linear, angular) in factors.items():
        speed, turn = drive.speed, drive.turn
        assert drive.press(key) is True
        assert (drive.speed, drive.turn) == (speed * linear, turn * angular)
        assert drive.velocity == (drive.speed, 0, 0, drive.turn)
    assert speed_line(0.5 * 1.1 * 1.1, 1.0) == \
        'currently:\tspeed 0.6050000000000001\tturn 1.0 '
    assert BANNER.splitlines()[1:3] == [
        'This node takes keypresses from the keyboard and publishes them',
        'as Twist/TwistStamped messages. It works best with a US keyboard layout.']
    assert BANNER.rstrip().endswith('CTRL-C to quit')


def test_version_and_no_terminal_say_what_it_is(ros_domain: int) -> None:
    program = [str(BIN / 'ros2'), 'run', 'teleop_twist_keyboard', 'teleop_twist_keyboard']
    version = subprocess.run([*program, '--version'], capture_output=True, text=True,
                             timeout=60, check=True)
    assert "robot_lab's stand-in for ros2/teleop_twist_keyboard 2.4.1 (Jazzy)" in \
        version.stdout
    piped = subprocess.run(program, stdin=subprocess.DEVNULL, capture_output=True,
                           text=True, timeout=60, check=False)
    assert piped.returncode == 1
    assert piped.stderr.strip().splitlines()[-1] == NO_TERMINAL


# -- the terminal program ---------------------------------------------------------------

class Terminal:
    """A program on a pty: what it printed, and keys typed to it."""

    def __init__(self, argv: list[str]) -> None:
        self.main, child = pty.openpty()
        self.proc = spawn(argv, stdin=child, stdout=child, stderr=child)
        os.close(child)
        self.seen = b''

    def read_until(self, text: bytes, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while text not in self.seen and time.monotonic() < deadline:
            ready, _, _ = select.select([self.main], [], [], 0.5)
            if ready:
                try:
                    self.seen += os.read(self.main, 4096)
                except OSError:
                    break
        assert text in self.seen, self.seen.decode(errors='replace')

    def type(self, keys: bytes) -> None:
        os.write(self.main, keys)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        os.close(self.main)


@pytest.fixture
def cmd_vel(ros_domain: int) -> Iterator[Inbox]:
    from geometry_msgs.msg import Twist

    inbox = Inbox('/cmd_vel', Twist)
    try:
        yield inbox
    finally:
        inbox.close()


def test_terminal_keys_publish_upstreams_twists(cmd_vel: Inbox) -> None:
    term = Terminal([str(BIN / 'ros2'), 'run', 'teleop_twist_keyboard',
                     'teleop_twist_keyboard'])
    try:
        term.read_until(b'currently:\tspeed 0.5\tturn 1.0 \r\n')
        text = term.seen.replace(b'\r\n', b'\n').decode()
        first_log = next(line for line in text.splitlines() if line.startswith('['))
        assert '[teleop_twist_keyboard]: teleop_twist_keyboard (robot_lab' in first_log
        assert "robot_lab's stand-in for ros2/teleop_twist_keyboard 2.4.1" in first_log
        assert BANNER + '\ncurrently:\tspeed 0.5\tturn 1.0 \n' in text
        # A key's one message sent before the publisher has matched the subscription is
        # lost, as a student's first key can be: press `i` until one arrives.
        got = cmd_vel.wait(lambda m: bool(m) and parts(m[-1]) == (0.5, 0, 0, 0, 0, 0),
                           'i drives forward at 0.5 m/s', poke=lambda: term.type(b'i'))

        def after(keys: bytes, expected: tuple[float, ...], what: str) -> None:
            count = len(cmd_vel.messages)
            term.type(keys)
            got = cmd_vel.wait(lambda m: len(m) >= count + len(keys), what)
            assert parts(got[-1]) == pytest.approx(expected), what

        after(b'q', (0.55, 0, 0, 0, 0, 0), 'q: 10 % faster, still forward')
        term.read_until(b'currently:\tspeed 0.55\tturn 1.1 \r\n')
        after(b'u', (0.55, 0, 0, 0, 0, 1.1), 'u: forward and left')
        after(b'x', (0.5 * 1.1 * 0.9, 0, 0, 0, 0, 1.1), 'x: only linear slower')
        after(b'J', (0, 0.495, 0, 0, 0, 0), 'J: strafe left')
        after(b'b', (0, 0, -0.495, 0, 0, 0), 'b: down')
        after(b'k', (0, 0, 0, 0, 0, 0), 'k: stop')
        after(b',', (-0.495, 0, 0, 0, 0, 0), ',: back')
        count = len(cmd_vel.messages)
        term.type(b'\x03')  # CTRL-C: a key in the raw terminal
        got = cmd_vel.wait(lambda m: len(m) > count, 'a last message on CTRL-C')
        assert parts(got[-1]) == (0, 0, 0, 0, 0, 0)
        assert term.proc.wait(timeout=15) == 0
        assert len(got) == count + 1  # CTRL-C itself published nothing but the zero
    finally:
        term.close()


def test_terminal_stamped_with_frame_and_speed_parameters(ros_domain: int) -> None:
    from geometry_msgs.msg import TwistStamped

    program = [str(BIN / 'ros2'), 'run', 'teleop_twist_keyboard', 'teleop_twist_keyboard',
               '--ros-args']
    inbox = Inbox('/cmd_vel', TwistStamped)
    # both at once: the refusal costs the test no start of its own
    refused = Terminal([*program, '-p', 'frame_id:=base_link'])
    term = Terminal([*program, '-p', 'stamped:=true', '-p', 'frame_id:=base_link',
                     '-p', 'speed:=1.0', '-p', 'turn:=2.0'])
    try:
        assert refused.proc.wait(timeout=30) == 1
        refused.read_until(b"'frame_id' can only be set when 'stamped' is True")
        term.read_until(b'currently:\tspeed 1.0\tturn 2.0 \r\n')
        got = inbox.wait(lambda m: bool(m) and parts(m[-1].twist) == (1.0, 0, 0, 0, 0, 2.0),
                         "u: forward and left at the parameters' speeds",
                         poke=lambda: term.type(b'u'))
        assert got[-1].header.frame_id == 'base_link' and got[-1].header.stamp.sec > 0
        count = len(inbox.messages)
        term.type(b'\x03')
        got = inbox.wait(lambda m: len(m) > count, 'a last message on CTRL-C')
        assert parts(got[-1].twist) == ZERO and got[-1].header.frame_id == 'base_link'
        assert term.proc.wait(timeout=15) == 0
    finally:
        refused.close()
        term.close()
        inbox.close()


# -- the notebook pad -------------------------------------------------------------------

def test_pad_publishes_while_held_and_stops_on_release(ros_domain: int) -> None:
    from geometry_msgs.msg import TwistStamped

    from robot_lab.widgets.teleop import Teleop

    inbox = Inbox('/pad_vel', TwistStamped)
    pad = Teleop('/pad_vel', rate=20.0, stamped=True, frame_id='base_link')
    try:
        box = pad.widget
        assert 'robot-lab-widget' in box._dom_classes
        model = pad._pad
        assert model is not None and model.bindings['shifted'][','] == '<'
        until_matched(pad)
        model.held = 'i'  # what a held button (or key) sets in the browser
        got = inbox.wait(lambda m: len(m) >= 4, 'held i publishes at the rate')
        assert {parts(m.twist) for m in got} == {(0.5, 0, 0, 0, 0, 0)}
        assert {m.header.frame_id for m in got} == {'base_link'}
        stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in got]
        assert stamps == sorted(stamps) and stamps[0] > 0
        # a speed key from the browser: 10 % faster, the slider follows, still held
        pad._from_browser(model, {'kind': 'key', 'key': 'w'}, None)
        assert pad._sliders['speed'].value == pytest.approx(0.55)
        inbox.wait(lambda m: parts(m[-1].twist) == pytest.approx((0.55, 0, 0, 0, 0, 0)),
                   'w speeds the held key up')
        pad._sliders['turn'].value = 2.0  # the slider sets turn
        model.held = 'L'
        inbox.wait(lambda m: parts(m[-1].twist) == pytest.approx((0, -0.55, 0, 0, 0, 0)),
                   'L strafes right')
        model.held = 'j'
        inbox.wait(lambda m: parts(m[-1].twist) == pytest.approx((0, 0, 0, 0, 0, 2.0)),
                   'j turns left at the slider turn')
        model.held = ''  # let go
        got = inbox.wait(lambda m: parts(m[-1].twist) == (0, 0, 0, 0, 0, 0),
                         'release publishes zero')
        sent = pad.sent
        pad._tick()  # the rate's timer fires: nothing while no key is held
        assert pad.sent == sent and pad.held == ''
        pad.press('o')  # from code, as a check cell drives it: the model follows
        assert model.held == 'o'
        inbox.wait(lambda m: parts(m[-1].twist) == pytest.approx((0.55, 0, 0, 0, 0, -2.0)),
                   'press from code')
        count = len(inbox.messages)
        pad.close()  # closing while held stops the robot
        got = inbox.wait(lambda m: len(m) > count and parts(m[-1].twist) == (0,) * 6,
                         'close publishes zero')
        assert 'closed' in repr(pad)
    finally:
        pad.close()
        inbox.close()


def until_matched(pad: Any, timeout: float = 20.0) -> None:
    """The pad's publisher has matched the test's subscription (else the first held
    message may be lost, and this test would count on it)."""
    deadline = time.monotonic() + timeout
    while pad._publisher.get_subscription_count() < 1:
        assert time.monotonic() < deadline, 'the pad never matched the subscription'
        time.sleep(0.02)


@pytest.mark.no_ros
def test_pad_refuses_frame_id_without_stamped() -> None:
    from robot_lab.errors import GraphError
    from robot_lab.widgets.teleop import Teleop

    with pytest.raises(GraphError, match="'frame_id' can only be set when 'stamped'"):
        Teleop('/x', frame_id='base_link')
