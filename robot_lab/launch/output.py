"""What a launch prints and logs, line for line as `ros2 launch` does.

Screen lines are `[LEVEL] [name]: msg` for the launcher itself and `[label] line` for a
child's output. Every launch gets a log directory (`$ROS_LOG_DIR`, else `$ROS_HOME/log`,
else `~/.ros/log`, then `<date>-<host>-<pid>`) holding `launch.log` (timestamped, as
launch writes it) and one `<label>.log` per process. The lines are also kept in memory,
so a notebook handle can filter and wait on them.
"""

from __future__ import annotations

import datetime
import os
import re
import socket
import threading
import time
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import IO

__all__ = ['LaunchOutput', 'OutputLine', 'log_root', 'make_log_dir']

# Which destinations each `output=` value sends a child's streams to (launch's aliases).
_SCREEN_STREAMS: dict[str, frozenset[str]] = {
    'screen': frozenset({'stdout', 'stderr'}),
    'both': frozenset({'stdout', 'stderr'}),
    'full': frozenset({'stdout', 'stderr'}),
    'log': frozenset({'stderr'}),
    'own_log': frozenset(),
}
_LAUNCH_LOG_OUTPUTS = frozenset({'log', 'both', 'full'})

# `[INFO] [1795295429.405599744] [sensor]: ...` as rcutils prints a ROS log line.
_ROS_LINE = re.compile(
    r'^\[(DEBUG|INFO|WARN|WARNING|ERROR|FATAL)\]\s+(?:\[[\d.]+\]\s+)?\[([^\]]+)\]')
_LEVELS = {'WARN': 'WARNING'}


@dataclass(frozen=True)
class OutputLine:
    """One line as it appeared (or would have) on screen, with where it came from."""

    time: float
    source: str  # 'launch', 'launch.user' or a process label such as 'sensor_node-1'
    level: str | None  # the log level when the line is a log record, else None
    logger: str | None  # the ROS logger name of a child's log line (e.g. 'sensor')
    stream: str  # 'launch', 'stdout' or 'stderr'
    text: str  # the full screen line, prefix included

    def __str__(self) -> str:
        return self.text


def log_root(env: dict[str, str] | None = None) -> Path:
    """The base log directory, chosen the way launch and rcl choose it."""
    environ = os.environ if env is None else env
    root = environ.get('ROS_LOG_DIR')
    if not root:
        home = environ.get('ROS_HOME') or os.path.join('~', '.ros')
        root = os.path.join(home, 'log')
    return Path(os.path.normpath(os.path.expanduser(root)))


def make_log_dir(root: Path | None = None) -> Path:
    """A fresh `<YYYY-MM-DD-HH-MM-SS-ffffff>-<host>-<pid>` directory, and `latest` -> it."""
    base = log_root() if root is None else root
    while True:
        stamp = datetime.datetime.now().strftime('%Y-%m-%d-%H-%M-%S-%f')
        path = base / f'{stamp}-{socket.gethostname()}-{os.getpid()}'
        try:
            path.mkdir(parents=True)
            break
        except FileExistsError:
            continue
    latest = base / 'latest'
    try:
        if latest.is_symlink():
            latest.unlink()
        if not latest.exists():
            latest.symlink_to(path, target_is_directory=True)
    except OSError:
        pass  # a shared log root another launch is renewing at the same moment
    return path


class LaunchOutput:
    """Routes launcher messages and child output to screen, log files and memory."""

    def __init__(self, screen: IO[str] | None = None, *, log_dir: Path | None = None,
                 debug: bool = False, keep: int = 20000) -> None:
        self.screen = screen
        self.debug = debug
        self._log_dir = log_dir
        self._launch_log: IO[str] | None = None
        self._own_logs: dict[str, IO[str]] = {}
        self._lines: deque[OutputLine] = deque(maxlen=keep)
        self._count = 0
        self._lock = threading.Lock()
        self.changed = threading.Condition(self._lock)

    @property
    def log_dir(self) -> Path:
        """The launch's log directory (created on first use)."""
        if self._log_dir is None:
            self._log_dir = make_log_dir()
        return self._log_dir

    def open(self) -> None:
        """Create the log directory and print launch's two opening lines."""
        self.log_dir.mkdir(parents=True, exist_ok=True)
        self._launch_log = (self.log_dir / 'launch.log').open('a', encoding='utf-8')
        self.launcher('INFO', 'launch', f'All log files can be found below {self.log_dir}')
        level = 'DEBUG' if self.debug else 'INFO'
        self.launcher('INFO', 'launch', f'Default logging verbosity is set to {level}')

    def close(self) -> None:
        with self._lock:
            for handle in [self._launch_log, *self._own_logs.values()]:
                if handle is not None:
                    handle.close()
            self._launch_log = None
            self._own_logs.clear()

    def launcher(self, level: str, name: str, message: str) -> None:
        """A message of the launcher itself: `[LEVEL] [name]: message`."""
        if level == 'DEBUG' and not self.debug:
            return
        now = time.time()
        text = f'[{level}] [{name}]: {message}'
        record = OutputLine(now, name, level, None, 'launch', text)
        with self._lock:
            self._emit(record, to_screen=True)
            if self._launch_log is not None:
                self._launch_log.write(f'{now:.7f} {text}\n')
                self._launch_log.flush()
            if name not in ('launch', 'launch.user'):
                self._own_log(name, text)

    def child(self, label: str, stream: str, output: str, line: str) -> None:
        """One line a child printed on `stream`, routed by its `output=` setting."""
        now = time.time()
        text = f'[{label}] {line}'
        match = _ROS_LINE.match(line)
        level = logger = None
        if match:
            level = _LEVELS.get(match.group(1), match.group(1))
            logger = match.group(2)
        record = OutputLine(now, label, level, logger, stream, text)
        to_screen = stream in _SCREEN_STREAMS.get(output, _SCREEN_STREAMS['log'])
        with self._lock:
            self._emit(record, to_screen=to_screen)
            if self._launch_log is not None and output in _LAUNCH_LOG_OUTPUTS:
                self._launch_log.write(f'{now:.7f} {text}\n')
                self._launch_log.flush()
            self._own_log(label, line)

    def _own_log(self, label: str, text: str) -> None:
        handle = self._own_logs.get(label)
        if handle is None:
            handle = (self.log_dir / f'{label}.log').open('a', encoding='utf-8')
            self._own_logs[label] = handle
        handle.write(text + '\n')
        handle.flush()

    def _emit(self, record: OutputLine, *, to_screen: bool) -> None:
        self._lines.append(record)
        self._count += 1
        if to_screen and self.screen is not None:
            try:
                self.screen.write(record.text + '\n')
                self.screen.flush()
            except (OSError, ValueError):
                self.screen = None  # the terminal went away; keep logging to files
        self.changed.notify_all()

    def lines(self) -> list[OutputLine]:
        """Every line kept so far (the newest `keep`)."""
        with self._lock:
            return list(self._lines)

    @property
    def count(self) -> int:
        """How many lines were emitted in total (grows monotonically)."""
        return self._count

    def since(self, count: int) -> tuple[list[OutputLine], int]:
        """Lines emitted after the first `count` (those still kept), and the new count."""
        with self._lock:
            new = self._count - count
            items = list(self._lines)[-new:] if new > 0 else []
            return items, self._count

    def wait(self, count: int, timeout: float) -> None:
        """Block until more than `count` lines were emitted, or `timeout` passed."""
        with self.changed:
            if self._count == count:
                self.changed.wait(timeout)
