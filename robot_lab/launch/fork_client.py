"""The launcher's side of the fork server (fork_server.py): which nodes it may start, and a
Popen-like handle for each node it forked.

Opt-in: `ROBOT_LAB_FORK_SERVER=1` in the launcher's environment. A node goes through the
server only if it is a `#!<this interpreter>` script of a package known to be safe to fork
(the kit's own nodes), not run through a shell, and its environment matches the server's
in everything the interpreter reads when it starts (only ROS's own variables, read at
`rclpy.init`, may differ). Anything else, and any failure of the server, is exec'd as
before. The handle reports what the server saw when it reaped the node, in Popen's terms.

Why opt-in (bench/bench_launch.py, 2026-11-26): it halves the CPU to a running system and
cuts private memory by ~25 MB per launch, and is faster on a moderately loaded host; but on
an oversubscribed one, the server's imports run in one process where three exec'd nodes
would get three shares of the CPU (slower to the first Status: line), and some tests count
a launcher's direct children (tests/test_graph_daemon.py). A node's parent is the server,
not the launcher (`ps -o ppid`); forked nodes share the server's hash seed.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Mapping
from typing import IO, Any

from robot_lab.launch.plan import ProcessSpec
from robot_lab.process import spawn

__all__ = ['ENABLE', 'SAFE_PACKAGES', 'ForkServer', 'ForkedProcess', 'enabled', 'interpreter_of']

ENABLE = 'ROBOT_LAB_FORK_SERVER'
SAFE_PACKAGES = frozenset({'robot_lab'})
# Read at rclpy.init or later, so a forked node may differ from the server in these.
_RUNTIME = ('ROS_', 'RMW_', 'RCUTILS_', 'RCL_', 'FASTRTPS_', 'FASTDDS_', 'AMENT_', 'COLCON_')
_READY_TIMEOUT = 120.0  # the server's imports, on a host as loaded as a class hub gets
_MESSAGE = 1 << 16


def enabled(environ: Mapping[str, str] | None = None) -> bool:
    """Whether launches here fork their Python nodes (ROBOT_LAB_FORK_SERVER=1)."""
    return (os.environ if environ is None else environ).get(ENABLE, '0') == '1'


def _startup(env: Mapping[str, str]) -> dict[str, str]:
    return {k: v for k, v in env.items() if not k.startswith(_RUNTIME)}


def interpreter_of(spec: ProcessSpec) -> str | None:
    """The `#!` interpreter of the node's script when the server may run it, else None."""
    if spec.shell or spec.package not in SAFE_PACKAGES or not spec.cmd:
        return None
    script = spec.cmd[0]
    if not os.path.isabs(script) or not os.access(script, os.X_OK):
        return None
    try:
        with open(script, 'rb') as file:
            first = file.readline(4096)
    except OSError:
        return None
    interpreter = first[2:].strip() if first.startswith(b'#!') else b''
    if not interpreter or b' ' in interpreter or b'\t' in interpreter:
        return None
    path = os.fsdecode(interpreter)
    return path if os.path.realpath(path) == os.path.realpath(sys.executable) else None


class ForkedProcess:
    """A node the server forked: the parts of subprocess.Popen the supervisor uses."""

    def __init__(self, server: ForkServer, pid: int, pidfd: int, args: list[str],
                 stdout: IO[bytes], stderr: IO[bytes]) -> None:
        self._server = server
        self.pid = pid
        self.args = args
        self.stdout: IO[bytes] | None = stdout
        self.stderr: IO[bytes] | None = stderr
        self.returncode: int | None = None
        self._pidfd: int | None = pidfd  # signals reach this process, never a reused pid

    def _exited(self, status: int) -> None:
        self.returncode = os.waitstatus_to_exitcode(status)
        if self._pidfd is not None:
            os.close(self._pidfd)
            self._pidfd = None

    def poll(self) -> int | None:
        if self.returncode is None:
            self._server.pump(0.0)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
            self._server.pump(left)
        return self.returncode

    def send_signal(self, sig: int) -> None:
        if self.poll() is None and self._pidfd is not None:
            signal.pidfd_send_signal(self._pidfd, sig)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


class ForkServer:
    """One fork server for one launch, started from the supervisor's thread (its parent-
    death signal is tied to that thread, like every child's)."""

    def __init__(self, env: Mapping[str, str]) -> None:
        self._env = _startup(env)
        self._ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._children: dict[int, ForkedProcess] = {}
        self._exits: dict[int, int] = {}
        self._replies: list[dict[str, Any]] = []
        self.error: str | None = None
        self._ready = False
        try:
            self._proc = spawn([sys.executable, '-m', 'robot_lab.launch.fork_server',
                                str(theirs.fileno())], env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, pass_fds=[theirs.fileno()])
        finally:
            theirs.close()

    def accepts(self, env: Mapping[str, str]) -> bool:
        return self.error is None and _startup(env) == self._env

    def start(self, spec: ProcessSpec, env: dict[str, str], cwd: str | None,
              interpreter: str) -> ForkedProcess | None:
        """Fork the node `spec` describes; None when it must be exec'd instead."""
        if not self.accepts(env) or not self._wait_ready():
            return None
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        null = os.open(os.devnull, os.O_RDONLY)
        request = {'script': spec.cmd[0], 'argv': spec.cmd[1:], 'env': env,
                   'cmdline': [interpreter, *spec.cmd], 'cwd': cwd or os.getcwd()}
        try:
            socket.send_fds(self._ours, [json.dumps(request).encode()], [null, out_w, err_w])
            reply = self._reply()
        except OSError as exc:
            self._fail(f'{exc}')
            reply = {}
        finally:
            for fd in (null, out_w, err_w):
                os.close(fd)
        if 'pid' not in reply:
            os.close(out_r)
            os.close(err_r)
            if 'error' in reply:
                self.error = str(reply['error'])
            return None
        child = ForkedProcess(self, reply['pid'], reply['pidfd'], list(spec.cmd),
                              os.fdopen(out_r, 'rb'), os.fdopen(err_r, 'rb'))
        self._children[child.pid] = child
        if child.pid in self._exits:
            child._exited(self._exits.pop(child.pid))
        return child

    def _wait_ready(self) -> bool:
        deadline = time.monotonic() + _READY_TIMEOUT
        while not self._ready and self.error is None and time.monotonic() < deadline:
            self.pump(deadline - time.monotonic())
        return self._ready and self.error is None

    def _reply(self) -> dict[str, Any]:
        while not self._replies and self.error is None:
            self.pump(None)
        return self._replies.pop(0) if self._replies else {}

    def pump(self, timeout: float | None) -> None:
        """Take the server's messages: readiness, replies, exits (waiting up to timeout)."""
        while self.error is None:
            ready, _, _ = select.select([self._ours], [], [], timeout)
            if not ready:
                return
            timeout = 0.0
            data, fds, _, _ = socket.recv_fds(self._ours, _MESSAGE, 1)
            if not data:
                self._fail('the fork server ended')
                return
            message = json.loads(data)
            if 'ready' in message:
                self._ready = True
            elif 'exit' in message:
                child = self._children.get(message['exit'])
                if child is None:
                    self._exits[message['exit']] = message['status']
                else:
                    child._exited(message['status'])
            else:
                if fds:
                    message['pidfd'] = fds[0]
                if not self._ready:  # an error before it was ready: it cannot fork
                    self.error = str(message.get('error', 'not ready'))
                self._replies.append(message)

    def _fail(self, reason: str) -> None:
        """The server is gone: its children died with it (parent-death signal)."""
        self.error = reason
        for child in self._children.values():
            if child.returncode is None:
                child._exited(signal.SIGKILL)  # a wait status: killed by SIGKILL

    def close(self) -> None:
        """Once every node has ended: the server exits (killing any node still there)."""
        with contextlib.suppress(OSError):
            self._ours.close()
        try:
            self._proc.wait(10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
