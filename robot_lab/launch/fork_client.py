"""The launcher's side of the fork server (fork_server.py): which nodes it may start, and a
Popen-like handle for each node it forked.

On by default; `ROBOT_LAB_FORK_SERVER=0` in the launcher's environment execs every node.
A node goes through the server only if it is a package's `#!<this interpreter>` script (the
kit's nodes and a student's ament_python ones alike), not run through a shell, and its
environment matches the server's in everything the interpreter reads when it starts (only
ROS's own variables, read at `rclpy.init`, may differ). Anything else, and any failure of
the server, is exec'd as before. A forked node is the server's child: the server sends its
exit status over the socket, and the handle (Popen's terms) reports it as Popen would an
exec'd child's; it signals the node through a pidfd (by pid where there is none: the node
is not reaped, so its pid is not reused, until the server has sent its status).

The server is started before the first node and imports what the nodes will; every node
waits for it rather than being exec'd meanwhile. For the kit's own package it starts before
the launch file is read (start_early). Launch -> first Status as a multiple of the bare
trio, three busy loops, 2026-11-28: beside a CI run, 3 A/B pairs, 1.62-2.00x before,
0.88-1.15x after (a second series of the same code: 1.26-1.43x); bench_launch --quick
--idle 1 --busy 3: 1.34x (5 runs), then 1.65, 1.34, 1.26x (9 runs each), against 1.65x
(5 runs) the day before: within the load's noise of 1.3. Measured (bench/bench_launch.py --quick
--quiet --fork-server both, 2 cores, 2026-11-26), launch -> first Status as a multiple of
three bare rclpy processes: exec 1.35-1.51x; the first node exec'd while the server imports
and the rest forked 1.02-1.07x, 78 MB USS; all forked 0.78-0.80x, 61 MB. With two busy
loops: exec 1.37-1.90x, first exec'd 1.76x, all forked 1.27x. An exec'd node importing
beside the server takes CPU from it, and the first Status needs all three nodes.
What still differs from exec: forked nodes share the server's str hash seed, and their
parent is the server (`ps`, psutil's children(): the launcher's grandchildren).
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
from robot_lab.linux import capabilities, procfs
from robot_lab.linux.pidfd import open_pidfd, send_signal
from robot_lab.process import spawn

__all__ = ['EARLY_PACKAGES', 'ENABLE', 'ForkServer', 'ForkedProcess', 'enabled', 'interpreter_of',
           'start_early']

ENABLE = 'ROBOT_LAB_FORK_SERVER'
# Packages whose launch starts a server before its file is read (start_early).
EARLY_PACKAGES = frozenset({'robot_lab'})
# Read at rclpy.init or later, so a forked node may differ from the server in these.
_RUNTIME = ('ROS_', 'RMW_', 'RCUTILS_', 'RCL_', 'FASTRTPS_', 'FASTDDS_', 'AMENT_', 'COLCON_')
_READY_TIMEOUT = 120.0  # the server's imports, on a host as loaded as a class hub gets
_MESSAGE = 1 << 16
_REPLY_TIMEOUT = 30.0  # a loaded host's fork takes well under a second
_GONE_POLL = 0.05  # a node whose server has ended, looked for without a pidfd


def enabled(environ: Mapping[str, str] | None = None) -> bool:
    """Whether launches here fork their Python nodes (yes unless ROBOT_LAB_FORK_SERVER=0
    or the `fork_server` capability is switched off)."""
    env = os.environ if environ is None else environ
    return env.get(ENABLE, '1') != '0' and not capabilities.disabled('fork_server', env)


def _startup(env: Mapping[str, str]) -> dict[str, str]:
    return {k: v for k, v in env.items() if not k.startswith(_RUNTIME)}


def start_early(package: str) -> ForkServer | None:
    """A server started before `package`'s launch file is read, when its nodes may be forked.

    A launcher reads the launch file before it knows its nodes, then waited for the server's
    imports; on a loaded host that chain of one process at a time got one share of the CPU
    while three exec'd nodes got three. Started first, the server imports while the file is
    parsed. Only for the kit's package, whose nodes' environment is known before the file
    is read; a student's package gets its server once the plan names its first node. The
    supervisor discards it (kills it at once) if no node needs it or its environment does
    not suit the first forkable node.
    """
    if package not in EARLY_PACKAGES or not enabled():
        return None
    from robot_lab.env import ros_environment

    try:
        return ForkServer(ros_environment())
    except OSError:
        return None


def interpreter_of(spec: ProcessSpec) -> str | None:
    """The `#!` interpreter of the node's script when the server may run it, else None."""
    if spec.shell or not spec.package or not spec.cmd:
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
    """A node the server forked: the parts of subprocess.Popen the supervisor uses. Its
    exit status comes from the server's socket (`ForkServer.pump`)."""

    def __init__(self, server: ForkServer, pid: int, args: list[str], stdout: IO[bytes],
                 stderr: IO[bytes]) -> None:
        self.pid = pid
        self.args = args
        self.stdout: IO[bytes] | None = stdout
        self.stderr: IO[bytes] | None = stderr
        self.returncode: int | None = None
        self._server = server
        self._pidfd: int | None = None
        with contextlib.suppress(ProcessLookupError):  # gone already: its status will say
            self._pidfd = open_pidfd(pid)

    def poll(self) -> int | None:
        if self.returncode is None:
            self._server.pump(0.0)
            self.returncode = self._server.exit_code(self.pid, self._pidfd)
            if self.returncode is not None and self._pidfd is not None:
                os.close(self._pidfd)
                self._pidfd = None
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        while (code := self.poll()) is None:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
            if self._server.error is None:
                self._server.pump(left)  # until its exit status (or another message)
            else:  # the server is gone: wait for the node to die with it
                waited = [self._pidfd] if self._pidfd is not None else []
                select.select(waited, [], [], _GONE_POLL if left is None
                              else min(left, _GONE_POLL))
        return code

    def send_signal(self, sig: int) -> None:
        if self.poll() is None:
            if self._pidfd is not None:
                send_signal(self._pidfd, sig)
            else:  # not reaped until the server has sent its status: the pid is the node's
                with contextlib.suppress(ProcessLookupError):
                    os.kill(self.pid, sig)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def _gone(pid: int, pidfd: int | None) -> bool:
    """Whether a node whose server has ended is gone (killed by its parent-death signal)."""
    if pidfd is not None:
        return bool(select.select([pidfd], [], [], 0)[0])
    return not procfs.process_running(pid)  # a zombie until init reaps it: gone


class ForkServer:
    """One fork server for one launch, started from the supervisor's thread (its
    parent-death signal, and so its nodes', is tied to that thread, as an exec'd node's)."""

    def __init__(self, env: Mapping[str, str]) -> None:
        self._env = _startup(env)
        self._ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._replies: list[dict[str, Any]] = []
        self._exits: dict[int, int] = {}  # pid -> exit status, until its handle takes it
        self.error: str | None = None
        self._ready = False
        try:
            self._proc = spawn([sys.executable, '-m', 'robot_lab.launch.fork_server',
                                str(theirs.fileno())], env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, pass_fds=[theirs.fileno()])
        finally:
            theirs.close()

    @property
    def pid(self) -> int:
        return self._proc.pid

    def fileno(self) -> int:
        """Readable when the server has sent something (an exit status): for a selector."""
        return self._ours.fileno()

    def exit_code(self, pid: int, pidfd: int | None) -> int | None:
        """Node `pid`'s exit status once the server has sent it (taken: asked once), or,
        the server gone, -SIGKILL once the node has died with it."""
        if pid in self._exits:
            return self._exits.pop(pid)
        if self.error is not None and _gone(pid, pidfd):
            return -signal.SIGKILL
        return None

    def accepts(self, env: Mapping[str, str]) -> bool:
        return self.error is None and _startup(env) == self._env

    def start(self, spec: ProcessSpec, env: dict[str, str], cwd: str | None,
              interpreter: str) -> ForkedProcess | None:
        """Fork the node `spec` describes; None when it must be exec'd instead."""
        if not self.accepts(env) or not self._warm():
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
            self.error, reply = f'{exc}', {}
        finally:
            for fd in (null, out_w, err_w):
                os.close(fd)
        if 'pid' not in reply:
            os.close(out_r)
            os.close(err_r)
            if 'error' in reply:
                self.error = str(reply['error'])
            return None
        return ForkedProcess(self, reply['pid'], list(spec.cmd), os.fdopen(out_r, 'rb'),
                             os.fdopen(err_r, 'rb'))

    def _warm(self) -> bool:
        """Whether to fork this node: once the server has imported (see the module's
        docstring for why a node waits for that rather than being exec'd meanwhile)."""
        deadline = time.monotonic() + _READY_TIMEOUT
        while not self._ready and self.error is None and time.monotonic() < deadline:
            self.pump(deadline - time.monotonic())
        return self._ready and self.error is None

    def _reply(self) -> dict[str, Any]:
        """The server's answer to a request: it forks in milliseconds, so one that has not
        answered in _REPLY_TIMEOUT is stuck; it is ended, and this node and the rest are
        exec'd."""
        deadline = time.monotonic() + _REPLY_TIMEOUT
        while not self._replies and self.error is None:
            left = deadline - time.monotonic()
            if left <= 0:
                self.error = f'the fork server did not answer within {_REPLY_TIMEOUT:.0f} s'
                self._proc.kill()
                break
            self.pump(left)
        return self._replies.pop(0) if self._replies else {}

    def pump(self, timeout: float | None) -> None:
        """Take the server's messages: readiness, replies, exit statuses (waiting up to
        timeout for the first)."""
        while self.error is None:
            ready, _, _ = select.select([self._ours], [], [], timeout)
            if not ready:
                return
            timeout = 0.0
            data = self._ours.recv(_MESSAGE)
            if not data:
                self.error = 'the fork server ended'
                return
            message = json.loads(data)
            if 'exit' in message:
                self._exits[int(message['exit'])] = int(message['code'])
            elif 'ready' in message:
                self._ready = True
            elif not self._ready:  # an error before it was ready: it cannot fork
                self.error = str(message.get('error', 'not ready'))
            else:
                self._replies.append(message)

    def discard(self) -> None:
        """End a server that forked nothing at once (a launch whose file failed to load,
        or whose nodes are all exec'd): waiting for its imports would only delay the exit."""
        with contextlib.suppress(OSError):
            self._ours.close()
        self._proc.kill()
        self._proc.wait()

    def close(self) -> None:
        """The server exits once its socket closes (after its nodes: the supervisor
        closes it once every node has ended; one left would die with the server)."""
        with contextlib.suppress(OSError):
            self._ours.close()
        try:
            self._proc.wait(10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
