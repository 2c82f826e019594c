"""`ros2 run turtlesim turtle_teleop_key`: drive turtle1 from the terminal's keys.

As Jazzy's teleop_turtle_key: node /teleop_turtle, parameters scale_linear and
scale_angular (2.0), one Twist on turtle1/cmd_vel per arrow key, rotate_absolute goals on
G|B|V|C|D|E|R|T, F cancels the rotation, Q quits. Keys are read one byte at a time from a
raw terminal, as upstream does (so the arrow keys' final bytes A-D are what count).
"""

from __future__ import annotations

import signal
import sys
import termios
import threading
from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.action.client import ActionClient
from turtlesim.action import RotateAbsolute

from robot_lab.keyboard_terminal import KeyTerminal, spin_while
from robot_lab.turtlesim.cpp_node import CppNode
from robot_lab.turtlesim.node import topic_qos

__all__ = ['KEYS', 'TeleopTurtle', 'main']

PROMPT = """Reading from keyboard
---------------------------
Use arrow keys to move the turtle.
Use G|B|V|C|D|E|R|T keys to rotate to absolute orientations. 'F' to cancel a rotation.
'Q' to quit."""

# byte → (linear, angular) or an absolute heading (rad), as upstream's switch
MOVES = {b'A': (1.0, 0.0), b'B': (-1.0, 0.0), b'C': (0.0, -1.0), b'D': (0.0, 1.0)}
HEADINGS = {b'g': 0.0, b't': 0.7854, b'r': 1.5708, b'e': 2.3562, b'd': 3.1416,
            b'c': -2.3562, b'v': -1.5708, b'b': -0.7854}
KEYS = {**MOVES, **HEADINGS}


class TeleopTurtle(CppNode):
    """Publishes the keys' Twists; sends and cancels rotate_absolute goals."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('teleop_turtle', **kwargs)
        self.declare_parameter('scale_angular', 2.0)
        self.declare_parameter('scale_linear', 2.0)
        self.twist = self.create_publisher(Twist, 'turtle1/cmd_vel', topic_qos())
        self.rotate = ActionClient(self, RotateAbsolute, 'turtle1/rotate_absolute')
        self.goal_handle: Any = None

    def key(self, byte: bytes) -> None:
        """One byte from the keyboard."""
        if byte in MOVES:
            linear, angular = MOVES[byte]
            twist = Twist()
            twist.angular.z = float(self.get_parameter('scale_angular').value) * angular
            twist.linear.x = float(self.get_parameter('scale_linear').value) * linear
            self.twist.publish(twist)
        elif byte in HEADINGS:
            future = self.rotate.send_goal_async(RotateAbsolute.Goal(theta=HEADINGS[byte]))
            future.add_done_callback(self._accepted)
        elif byte == b'f' and self.goal_handle is not None:
            self.goal_handle.cancel_goal_async()

    def _accepted(self, future: Any) -> None:
        self.goal_handle = future.result()


def main(args: Sequence[str] | None = None) -> None:
    """The `turtle_teleop_key` executable (exit status 1 without a terminal)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    try:
        terminal = KeyTerminal(sys.stdin.fileno())
    except (termios.error, OSError, ValueError):
        print('turtle_teleop_key reads keys from a terminal: run it in a terminal '
              '(JupyterLab: File > New > Terminal), not from a notebook cell or a pipe',
              file=sys.stderr)
        raise SystemExit(1) from None
    running = threading.Event()
    running.set()
    signal.signal(signal.SIGINT, lambda *_: running.clear())
    signal.signal(signal.SIGTERM, lambda *_: running.clear())
    rclpy.init(args=list(args) if args is not None else sys.argv,
               signal_handler_options=SignalHandlerOptions.NO)
    node = TeleopTurtle()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = spin_while(executor, running)
    print(PROMPT, flush=True)
    try:
        with terminal:
            _drive(node, terminal, running)
    finally:
        running.clear()
        spinner.join(timeout=2.0)
        executor.shutdown()
        node.destroy_node()
        rclpy.utilities.try_shutdown()


def _drive(node: TeleopTurtle, terminal: KeyTerminal, running: threading.Event) -> None:
    for chunk in terminal.chunks(running):
        for value in chunk:  # byte by byte, as upstream reads them
            byte = bytes([value])
            if byte == b'q':
                return
            node.key(byte)


if __name__ == '__main__':
    main()
