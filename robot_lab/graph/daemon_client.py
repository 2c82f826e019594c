"""The graph daemon as other processes see it: bind its socket, start it, ask it, stop it.

A one-shot command (`robot-lab node list`) needs only this side and must answer within
milliseconds, so this module imports neither rclpy nor the graph modules; the daemon
process itself (daemon.py) keeps a warm rclpy session. The protocol is one JSON line each
way.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import socket
import subprocess
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

from robot_lab.env import switched_on
from robot_lab.errors import GraphError
from robot_lab.graph.expected import graph_dir
from robot_lab.linux.procfs import process_running

__all__ = [
    'AUTOSTART_VARIABLE',
    'IDLE_TIMEOUT',
    'NO_DAEMON_VARIABLE',
    'OWNER_VARIABLE',
    'QUERY_TIMEOUT',
    'Listener',
    'disabled',
    'is_running',
    'query',
    'socket_path',
    'start',
    'start_for_later',
    'stop',
    'wait_until_running',
]

# `ros2 daemon start`'s daemon also exits after two hours without a request.
IDLE_TIMEOUT = 2 * 60 * 60.0
# How long a command waits for the daemon's answer before asking the graph itself: above
# the longest the daemon settles an answer (settler.Rules.names_timeout, counted in time the
# daemon ran), with room for a host that runs it only part of the time.
QUERY_TIMEOUT = 20.0
# Set (to anything but 0) to make every command use its own session, like --no-daemon.
NO_DAEMON_VARIABLE = 'ROBOT_LAB_NO_DAEMON'
# Set to 0 to keep graph verbs from starting a daemon when none runs (the test suite: a
# daemon per test domain would outlive each run by up to IDLE_TIMEOUT).
AUTOSTART_VARIABLE = 'ROBOT_LAB_DAEMON_AUTOSTART'
# The process whose end ends a daemon a command starts (default: the command's session).
OWNER_VARIABLE = 'ROBOT_LAB_DAEMON_OWNER'
# In the daemon's command line, so `pgrep -f robot-lab` finds it like the kit's other
# processes.
_FLAG = '--robot-lab-graph-daemon'
_SOCKET = 'daemon.sock'
_LOCK = 'daemon.lock'


def socket_path(env: Mapping[str, str] | None = None) -> Path:
    return graph_dir(env) / _SOCKET


def disabled() -> bool:
    """True when the user asked for no daemon (ROBOT_LAB_NO_DAEMON=1)."""
    return switched_on(NO_DAEMON_VARIABLE)


def _connect(path: Path, timeout: float) -> socket.socket | None:
    if not path.exists():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(timeout)
    try:
        sock.connect(str(path))
    except OSError:  # a stale socket file: its daemon is gone
        sock.close()
        return None
    return sock


def query(op: str, *, timeout: float = QUERY_TIMEOUT, env: Mapping[str, str] | None = None,
          **params: Any) -> Any | None:
    """The daemon's answer to `op`, or None when no daemon serves this graph.

    None (rather than an error) also when the daemon does not answer within `timeout`, or
    does not know `op` (it is older than this client): the caller then asks the graph
    itself, which is slower but still right.
    """
    if disabled():
        return None
    sock = _connect(socket_path(env), timeout)
    if sock is None:
        return None
    with sock:
        try:
            sock.sendall(json.dumps({'op': op, **params}).encode() + b'\n')
            chunks = []
            while chunk := sock.recv(65536):
                chunks.append(chunk)
        except OSError:
            return None
    try:
        reply = json.loads(b''.join(chunks))
    except ValueError:
        return None
    if reply.get('unknown'):
        return None
    if 'error' in reply:
        raise GraphError(reply['error'], fix=reply.get('fix'))
    return reply.get('result')


def is_running(env: Mapping[str, str] | None = None) -> bool:
    """True when a daemon answers on this graph's socket."""
    sock = _connect(socket_path(env), 2.0)
    if sock is None:
        return False
    sock.close()
    return True


class Listener:
    """The daemon's bound socket and lock, made before the daemon process exists.

    A launcher binds it first thing (socket activation, as systemd does it): a
    `node list` typed while the daemon is still starting queues on the socket and gets a
    warm answer, instead of finding nothing and starting a cold session of its own.
    """

    def __init__(self, sock: socket.socket, lock: IO[str], path: Path) -> None:
        self.socket, self.lock, self.path = sock, lock, path
        self.closed = False

    @classmethod
    def bind(cls, env: Mapping[str, str] | None = None) -> Listener | None:
        """Bind this graph's socket; None if another daemon (or launcher) holds it."""
        try:
            directory = graph_dir(env, create=True)
            lock = open(directory / _LOCK, 'a')  # noqa: SIM115 - lives as long as the daemon
        except OSError:
            return None  # no runtime directory: commands use their own sessions
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            return None
        path = directory / _SOCKET
        with contextlib.suppress(FileNotFoundError):
            path.unlink()  # left by a daemon that was killed
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            sock.bind(str(path))
            sock.listen(64)
        except OSError:
            sock.close()
            lock.close()
            return None
        return cls(sock, lock, path)

    def fds(self) -> tuple[int, int]:
        return self.socket.fileno(), self.lock.fileno()

    def close(self, unlink: bool = True) -> None:
        """Close this process's copies (a daemon that inherited them keeps serving)."""
        if self.closed:
            return
        self.closed = True
        if unlink:
            with contextlib.suppress(OSError):
                self.path.unlink()
        self.socket.close()
        self.lock.close()


def start(*, detached: bool, idle_timeout: float = IDLE_TIMEOUT,
          env: Mapping[str, str] | None = None, listener: Listener | None = None,
          owner: int | None = None, nice: int = 0) -> subprocess.Popen[bytes]:
    """Start a daemon for the graph of `env` (default: this process's environment).

    `detached`: its own session, outliving the caller until its idle timeout (what
    `robot-lab daemon start` wants). Otherwise it is the caller's child and dies with it
    (what a launcher wants). `listener`: a socket the caller bound already (the daemon
    inherits it; the caller should then close its copy with `unlink=False`). `owner`: a
    process whose end (even by `kill -9`) ends the daemon too, e.g. the JupyterLab that
    `./kit start` runs. `nice`: a lower CPU priority, so a daemon started beside nodes does
    not slow their start-up. A second daemon for a graph that has one exits at once.
    """
    from robot_lab.env import ros_environment
    from robot_lab.process import spawn

    child_env = ros_environment(env)
    child_env.setdefault('OPENBLAS_NUM_THREADS', '1')  # see robot_lab.cli.main
    cmd = [sys.executable, '-m', 'robot_lab.graph.daemon', _FLAG,
           '--idle-timeout', f'{idle_timeout:g}']
    if owner is not None:
        cmd += ['--owner', str(owner)]
    if nice:
        cmd += ['--nice', str(nice)]
    fds: tuple[int, ...] = ()
    if listener is not None:
        fds = listener.fds()
        cmd += ['--listen-fd', str(fds[0]), '--lock-fd', str(fds[1])]
    if detached:
        return subprocess.Popen(cmd, env=child_env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True, pass_fds=fds)
    return spawn(cmd, env=child_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                 pass_fds=fds)


def start_for_later(env: Mapping[str, str] | None = None,
                    owner: int | None = None) -> subprocess.Popen[bytes] | None:
    """Start a daemon for this graph when none serves it, without waiting for it.

    What ros2cli does when a command finds no daemon: this command answers from its own
    session, the next ones get warm, complete answers (a participant started outside the
    kit announces itself only every 3 s, so a cold command can miss it). The daemon ends
    with `owner`: by default the process OWNER_VARIABLE names (a kernel names itself), else
    the caller's session (its terminal, a CI job); or after IDLE_TIMEOUT. It runs at a
    lower CPU priority than the command that started it.
    """
    if disabled() or os.environ.get(AUTOSTART_VARIABLE, '1') == '0':
        return None
    if owner is None:
        owner = _named_owner()
        if owner in (os.getpid(), 1):
            return None  # nobody to outlive: a daemon started now would only exit again
    if owner is None or not process_running(owner):
        return None
    listener = Listener.bind(env)
    if listener is None:
        return None  # a daemon (or a launch about to start one) holds this graph
    try:
        return start(detached=True, env=env, listener=listener, owner=owner, nice=10)
    except OSError:
        return None
    finally:
        listener.close(unlink=False)


def _named_owner() -> int | None:
    """The process a daemon started by a command should end with.

    A notebook's `!ros2 …` runs in a session of its own (IPython gives each `!` command a
    pseudo-terminal), led by a shell that ends with the command: a daemon that ended with
    that session ended at once, and every command in the notebook was cold. The kernel
    names itself in OWNER_VARIABLE (grading.setup).
    """
    named = os.environ.get(OWNER_VARIABLE, '').strip()
    if named.isdigit():
        return int(named)
    try:
        return os.getsid(0)
    except OSError:
        return None


def wait_until_running(timeout: float = 10.0, env: Mapping[str, str] | None = None,
                       proc: subprocess.Popen[bytes] | None = None) -> bool:
    """Poll until the daemon answers (or `proc`, the one being started, has exited)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if is_running(env):
            return True
        if proc is not None and proc.poll() is not None:
            return is_running(env)
        time.sleep(0.02)
    return False


def stop(timeout: float = 10.0, env: Mapping[str, str] | None = None) -> bool:
    """Ask the daemon to exit and wait until its socket is gone; False if none was running."""
    if not is_running(env):
        return False
    with contextlib.suppress(GraphError):
        query('stop', timeout=timeout, env=env)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and is_running(env):
        time.sleep(0.02)
    return True
