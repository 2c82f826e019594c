"""Keys typed in a terminal for `ros2 bag play|record`, as ros-tooling's keyboard_handler
reads them: unbuffered and unechoed (cbreak; Ctrl-C still interrupts), restored on exit.

Without a terminal on stdin the keys are still announced and then ignored, with the
handler's own line, as rosbag2 does.
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable, Sequence

from robot_lab.keyboard_terminal import KeyTerminal

__all__ = ['CURSOR_DOWN', 'CURSOR_RIGHT', 'CURSOR_UP', 'SPACE', 'KeyBinding', 'listen',
           'unchanged']

SPACE, CURSOR_RIGHT, CURSOR_UP, CURSOR_DOWN = b' ', b'\x1b[C', b'\x1b[A', b'\x1b[B'
_NAMES = {SPACE: 'SPACE', CURSOR_RIGHT: 'CURSOR_RIGHT', CURSOR_UP: 'CURSOR_UP',
          CURSOR_DOWN: 'CURSOR_DOWN'}

# (key, what it does as rosbag2 words it, the action)
KeyBinding = tuple[bytes, str, Callable[[], object]]


def unchanged() -> None:
    """Nothing to restore: the terminal was never changed."""


def listen(bindings: Sequence[KeyBinding], log: Callable[[str, str], None],
           err: Callable[[str], None]) -> Callable[[], None]:
    """Announce the keys (`Press SPACE for …`), then run each binding's action when its key
    is typed; returns what restores the terminal."""
    try:
        fd = sys.stdin.fileno()
        terminal = os.isatty(fd)
    except (AttributeError, ValueError, OSError):
        terminal = False
    keys = None
    if terminal:
        keys = KeyTerminal(fd)
        keys.start()  # before the keys are announced: a key typed after them counts
    for key, what, _action in bindings:
        log('INFO', f'Press {_NAMES[key]} for {what}')
    if keys is None:
        err('stdin is not a terminal device. Keyboard handling disabled.')
        return unchanged
    actions = {key: action for key, _what, action in bindings}

    def read_keys() -> None:
        while True:
            try:
                data = os.read(fd, 32)
            except OSError:
                return
            if not data:
                return
            while data:  # an arrow key is three bytes; several keys may come at once
                size = 3 if data.startswith(b'\x1b[') else 1
                key, data = data[:size], data[size:]
                action = actions.get(key)
                if action is not None:
                    action()

    threading.Thread(target=read_keys, name='robot_lab-bag-keys', daemon=True).start()
    return keys.restore

