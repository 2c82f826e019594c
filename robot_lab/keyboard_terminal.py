"""A terminal read key by key, for the programs a student drives from the keyboard.

turtle_teleop_key, teleop_twist_keyboard and `ros2 bag play|record` all take keys as they
are typed: no echo, no line buffering, the terminal restored however the program ends.
teleop_twist_keyboard also makes CTRL-C a key (its quit key), as upstream's raw terminal
does. The teleop programs read keys on the main thread and spin their node on another.
"""

from __future__ import annotations

import os
import select
import termios
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rclpy.executors import Executor

__all__ = ['KeyTerminal', 'spin_while']

# how often a wait for a key (and the spin loop) looks whether the program still runs
POLL_S = 0.1


class KeyTerminal:
    """`fd`'s terminal without echo or line buffering inside `with` (or start/restore).

    Constructing it raises termios.error (or OSError) when `fd` is not a terminal, so a
    program can refuse with its own line before it changes anything.
    """

    def __init__(self, fd: int, *, ctrl_c_is_key: bool = False) -> None:
        self.fd = fd
        self.ctrl_c_is_key = ctrl_c_is_key
        self.saved = termios.tcgetattr(fd)

    def start(self) -> None:
        mode = termios.tcgetattr(self.fd)
        if self.ctrl_c_is_key:  # raw: no signal keys, no input translation
            mode[0] &= ~(termios.ICRNL | termios.IXON | termios.ISTRIP)
            mode[3] &= ~(termios.ISIG | termios.IEXTEN)
        mode[3] &= ~(termios.ICANON | termios.ECHO)
        mode[6][termios.VMIN] = 1
        mode[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSANOW, mode)

    def restore(self) -> None:
        termios.tcsetattr(self.fd, termios.TCSADRAIN, self.saved)

    def __enter__(self) -> KeyTerminal:
        self.start()
        return self

    def __exit__(self, *_: object) -> None:
        self.restore()

    def chunks(self, running: threading.Event, size: int = 64) -> Iterator[bytes]:
        """The bytes typed, as they come, until `running` clears or the terminal closes."""
        while running.is_set():
            ready, _, _ = select.select([self.fd], [], [], POLL_S)
            if not ready:
                continue
            try:
                data = os.read(self.fd, size)
            except OSError:
                return
            if not data:
                return
            yield data


def spin_while(executor: Executor, running: threading.Event) -> threading.Thread:
    """A daemon thread spinning `executor` until `running` clears (the caller joins it)."""

    def spin() -> None:
        while running.is_set():
            executor.spin_once(timeout_sec=POLL_S)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    return thread
