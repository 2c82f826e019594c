"""`ros2 run teleop_twist_keyboard teleop_twist_keyboard`: drive a robot from the terminal.

robot_lab's stand-in for ros2/teleop_twist_keyboard 2.4.1 (Jazzy), written for the kit
from upstream's documented behaviour: node /teleop_twist_keyboard, a Twist (or with
`stamped:=true` a TwistStamped carrying `frame_id`) on `cmd_vel` for every key, read-only
parameters `stamped`, `frame_id`, `speed` (0.5) and `turn` (1.0), the key map of `keys`,
CTRL-C (a key: the terminal is raw) quits and a zero Twist is the last message. It says
what it is on its first log line and with `--version`.
"""

from __future__ import annotations

import codecs
import signal
import sys
import termios
import threading
from collections.abc import Sequence

from robot_lab.keyboard_teleop.keys import BANNER, QUIT, Drive, speed_line, twist_message
from robot_lab.keyboard_terminal import KeyTerminal, spin_while

__all__ = ['NO_TERMINAL', 'TeleopKeyboard', 'main', 'version_line']

UPSTREAM = '2.4.1'
NO_TERMINAL = ('teleop_twist_keyboard reads keys from a terminal: run it in a terminal '
               '(JupyterLab: File > New > Terminal), or drive from a notebook with '
               'robot_lab.teleop()')


def version_line() -> str:
    from robot_lab import __version__
    return (f"teleop_twist_keyboard (robot_lab {__version__}): robot_lab's stand-in for "
            f"ros2/teleop_twist_keyboard {UPSTREAM} (Jazzy), not upstream's program")


class TeleopKeyboard:
    """The node: its parameters, its publisher, and the keys it is given."""

    def __init__(self) -> None:
        from rcl_interfaces.msg import ParameterDescriptor
        from rclpy.node import Node

        self.node = Node('teleop_twist_keyboard')
        fixed = ParameterDescriptor(read_only=True)  # upstream reads them once, at start
        self.stamped = bool(self.node.declare_parameter('stamped', False, fixed).value)
        self.frame_id = str(self.node.declare_parameter('frame_id', '', fixed).value)
        speed = float(self.node.declare_parameter('speed', 0.5, fixed).value)
        turn = float(self.node.declare_parameter('turn', 1.0, fixed).value)
        self.drive = Drive(speed=speed, turn=turn)
        from geometry_msgs.msg import Twist, TwistStamped

        kind = TwistStamped if self.stamped else Twist
        self.publisher = self.node.create_publisher(kind, 'cmd_vel', 10)

    def key(self, key: str) -> list[str]:
        """Apply one key and publish; the lines to print (a speed change shows the speeds,
        and every 15th the banner again, as upstream does)."""
        lines: list[str] = []
        if self.drive.press(key):
            lines.append(speed_line(self.drive.speed, self.drive.turn))
            if self.drive.speed_changes % 15 == 0:
                lines.append(BANNER)
        self.publish()
        return lines

    def publish(self) -> None:
        stamp = self.node.get_clock().now().to_msg() if self.stamped else None
        self.publisher.publish(twist_message(self.drive.velocity, self.stamped,
                                             self.frame_id, stamp))

    def stop(self, timeout: float = 1.0) -> None:
        """The last message: zero; waits (bounded) until the subscribers acknowledged it."""
        from rclpy.duration import Duration

        self.drive.stop()
        self.publish()
        self.publisher.wait_for_all_acked(Duration(seconds=timeout))


def main(argv: Sequence[str] | None = None) -> None:
    """The executable (exit status 1 without a terminal or with bad parameters)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from rclpy.utilities import remove_ros_args

    args = list(sys.argv if argv is None else argv)
    if '--version' in remove_ros_args(args)[1:]:
        print(version_line())
        return
    try:
        terminal = KeyTerminal(sys.stdin.fileno(), ctrl_c_is_key=True)
    except (termios.error, OSError, ValueError):
        print(NO_TERMINAL, file=sys.stderr)
        raise SystemExit(1) from None
    running = threading.Event()
    running.set()
    for number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(number, lambda *_: running.clear())
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    teleop: TeleopKeyboard | None = None
    executor = SingleThreadedExecutor()
    spinner: threading.Thread | None = None
    try:
        teleop = TeleopKeyboard()
        log = teleop.node.get_logger()
        log.info(version_line())
        if teleop.frame_id and not teleop.stamped:
            log.error("'frame_id' can only be set when 'stamped' is True — fix: add "
                      '-p stamped:=true, or leave frame_id out')
            raise SystemExit(1)
        executor.add_node(teleop.node)
        spinner = spin_while(executor, running)
        _drive(teleop, terminal, running)
    finally:
        running.clear()
        if spinner is not None:
            spinner.join(timeout=2.0)
        executor.shutdown()
        if teleop is not None:
            teleop.node.destroy_node()
        rclpy.utilities.try_shutdown()


def _drive(teleop: TeleopKeyboard, terminal: KeyTerminal, running: threading.Event) -> None:
    try:
        with terminal:  # raw before the banner: a key typed once it shows is never echoed
            print(BANNER, flush=True)
            print(speed_line(teleop.drive.speed, teleop.drive.turn), flush=True)
            decoder = codecs.getincrementaldecoder('utf-8')(errors='replace')
            for chunk in terminal.chunks(running):
                for key in decoder.decode(chunk):
                    if key == QUIT:
                        return
                    for line in teleop.key(key):
                        print(line, flush=True)
    finally:
        teleop.stop()


if __name__ == '__main__':
    main()
