"""The launcher's fork server: rclpy imported once, each Python node forked from it.

A node exec'd on its own spends ~0.2 s of CPU importing rclpy, numpy and its messages, and
holds that heap privately. Forked from a process that has already imported them (and not
yet called `rclpy.init`: no DDS participant, no threads), it skips the imports and shares
those pages copy-on-write with its siblings.

A forked node must look exactly like the exec'd one, so the child, before running the
node's script as `python SCRIPT ARGS` would:
- points its command line and environment (`ps`, /proc/PID/cmdline and environ) at new
  copies of the node's own, by prctl(PR_SET_MM_MAP), which needs no privilege, and names
  itself after the script (PR_SET_NAME, as exec does);
- takes the node's stdin/stdout/stderr, cwd and environment (os.environ, so C sees it too),
  closes every other descriptor, and resets SIGINT/SIGTERM/SIGCHLD as a fresh process has
  them; it stays in the launcher's process group and session;
- dies with the server (PR_SET_PDEATHSIG), which dies with the launcher: no node outlives
  its launcher, even after `kill -9`;
- exits as the interpreter would: the exit code of SystemExit, 1 after a traceback, or
  killed by SIGINT after an uncaught KeyboardInterrupt.

A node is the server's child (a plain os.fork, linux/fork.py says why), so the server reaps
it (woken by SIGCHLD, no thread: a thread would make the next fork unsafe) and sends its
exit status to the launcher, which reports it as it would an exec'd child's.

The server takes SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGUSR1/2 by signalfd: one a node
sent its parent goes on to the launcher (as it would reach an exec'd node's parent); any
other is dropped (a terminal's Ctrl-C reaches the whole process group, the launcher
included, and the nodes must outlive it to shut down cleanly). It answers each request with
{"pid": N} and each exit with {"exit": N, "code": C} (C as Popen's returncode: negative for
a signal), and exits when the launcher closes its socket. Run as
`python -m robot_lab.launch.fork_server FD`, FD a SOCK_SEQPACKET socket to the launcher
(robot_lab/launch/fork_client.py speaks to it).
"""

from __future__ import annotations

import builtins
import contextlib
import gc
import importlib
import io
import json
import os
import select
import signal
import socket
import sys
import threading
import traceback
import types
from collections.abc import Callable, Sequence
from importlib.machinery import SourceFileLoader
from types import TracebackType
from typing import Any

from robot_lab.linux.fork import fork, native_threads
from robot_lab.linux.prctl import set_name, set_parent_death_signal, set_process_image
from robot_lab.linux.signals import SignalReader

__all__ = ['PRELOAD', 'main']

# What the kit's node scripts import (kept in step with robot_lab/nodes/).
PRELOAD = (
    'rclpy', 'rclpy.node', 'rclpy.executors', 'rclpy.signals', 'rclpy.parameter',
    'rclpy.action', 'std_msgs.msg', 'geometry_msgs.msg', 'rcl_interfaces.msg',
    'robot_lab.nodes.base', 'robot_lab.nodes.sensor_node', 'robot_lab.nodes.controller_node',
    'robot_lab.nodes.robot_node',
)
MAX_MESSAGE = 1 << 20
# What an exec'd node could send its parent, the launcher, that the server must pass on.
RELAYED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1,
           signal.SIGUSR2)
def _exit_code(exc: SystemExit) -> int:
    """What the interpreter exits with for an uncaught SystemExit."""
    code = exc.code
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    print(code, file=sys.stderr)
    return 1


def _finish() -> None:
    """What Py_FinalizeEx does first: join non-daemon threads, atexit, flush."""
    threading._shutdown()  # type: ignore[attr-defined]  # the interpreter's own join
    import atexit

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()


def _script_traceback(tb: TracebackType | None, script: str) -> TracebackType | None:
    """The traceback from the script's own frame on, as `python SCRIPT` prints it."""
    while tb is not None and tb.tb_frame.f_code.co_filename != script:
        tb = tb.tb_next
    return tb


def _run_script(cmdline: list[str], script: str, argv: list[str]) -> int:
    """`python SCRIPT ARGV...` in this process, as the interpreter runs it; the exit code."""
    sys.argv = [script, *argv]
    sys.orig_argv = list(cmdline)
    sys.path[0] = os.path.dirname(os.path.realpath(script))
    # A folder on the path that did not exist when the server looked (a package built
    # since) is cached as "no finder": an exec'd interpreter would look again.
    for folder in [f for f, finder in sys.path_importer_cache.items() if finder is None]:
        del sys.path_importer_cache[folder]
    importlib.invalidate_caches()
    main = types.ModuleType('__main__')
    main.__dict__.update(__file__=script, __cached__=None, __builtins__=builtins,
                         __loader__=SourceFileLoader('__main__', script))
    sys.modules['__main__'] = main
    interrupted = False
    try:
        with io.open_code(script) as source:
            code = compile(source.read(), script, 'exec')
        exec(code, main.__dict__)  # what `python SCRIPT` does
        status = 0
    except SystemExit as exc:
        status = _exit_code(exc)
    except BaseException as exc:  # the interpreter prints any uncaught exception
        shown = _script_traceback(exc.__traceback__, script)
        exc.__traceback__ = shown  # the hook prints the exception's own traceback
        sys.excepthook(type(exc), exc, shown)
        status, interrupted = 1, isinstance(exc, KeyboardInterrupt)
    _finish()
    if interrupted:  # as CPython: die by the signal, so the parent sees SIGINT
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
    return status


def _become(request: dict[str, Any], fds: list[int], server: int) -> None:
    """In the forked child: turn into the node the request describes, run it, exit."""
    code = 1
    try:
        set_parent_death_signal(signal.SIGKILL)
        if os.getppid() != server:
            os._exit(1)  # the server died before the parent-death signal was armed
        signal.set_wakeup_fd(-1)  # the server's, closed below
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
        os.closerange(3, os.sysconf('SC_OPEN_MAX'))
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_SETMASK, set())
        os.chdir(request['cwd'])
        env: dict[str, str] = request['env']
        os.environ.clear()
        os.environ.update(env)
        script, argv = request['script'], request['argv']
        set_process_image(request['cmdline'], env)
        set_name(os.path.basename(script))
        code = _run_script(request['cmdline'], script, argv)
    except BaseException:  # never return into the server's loop
        traceback.print_exc()
    finally:
        os._exit(code)


class _Server:
    def __init__(self, sock: socket.socket, fork: Callable[[], int] = fork,
                 signals: SignalReader | None = None) -> None:
        self.sock = sock
        self.fork = fork
        self.signals = signals
        self.children: set[int] = set()
        # The threads the preload left (this one, LTTng-UST's listeners): any other, from
        # Python or a library, could hold a lock the child would then never see released.
        self.threads = native_threads()
        # SIGCHLD wakes the loop through this pipe (the C handler writes to it at once).
        self.wake, wake_w = os.pipe()
        for fd in (self.wake, wake_w):
            os.set_blocking(fd, False)
        signal.set_wakeup_fd(wake_w)
        signal.signal(signal.SIGCHLD, lambda *_: None)

    def send(self, message: dict[str, Any]) -> None:
        self.sock.send(json.dumps(message).encode())

    def serve(self) -> None:
        """Fork and reap until the launcher closes its end; the nodes still running then
        die with this process (their parent-death signal)."""
        self.send({'ready': os.getpid()})
        watched = [self.sock.fileno(), self.wake]
        if self.signals is not None:
            watched.append(self.signals.fileno())
        while True:
            ready, _, _ = select.select(watched, [], [])
            if self.wake in ready:
                with contextlib.suppress(BlockingIOError):
                    while os.read(self.wake, 4096):
                        pass
                self.reap()
            if self.signals is not None and self.signals.fileno() in ready:
                self.relay(self.signals.read())
            if self.sock.fileno() in ready and not self.request():
                return

    def reap(self) -> None:
        """Send the exit status of each child that has ended."""
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            self.children.discard(pid)
            self.send({'exit': pid, 'code': os.waitstatus_to_exitcode(status)})

    def relay(self, taken: list[tuple[int, int]]) -> None:
        """A signal a node sent its parent goes on to the launcher, which an exec'd node's
        parent is (a node that SIGTERMs its parent stops the launch; a grading job records
        it). Any other sender's is dropped: a process group's Ctrl-C reached the launcher
        itself."""
        for signum, sender in taken:
            if sender in self.children:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(os.getppid(), signum)

    def request(self) -> bool:
        """Fork one node; False once the launcher has closed its end."""
        data, fds, _, _ = socket.recv_fds(self.sock, MAX_MESSAGE, 4)
        if not data:
            return False
        try:
            request = json.loads(data)
            if threading.active_count() != 1 or native_threads() != self.threads:
                raise RuntimeError('the fork server has threads: forking it is unsafe')
            server = os.getpid()
            pid = self.fork()
            if pid == 0:
                _become(request, fds, server)
            self.children.add(pid)
            self.send({'pid': pid})
        except Exception as exc:  # the launcher execs the node instead
            self.send({'error': f'{type(exc).__name__}: {exc}'})
        finally:
            for fd in fds:
                os.close(fd)
        return True


def preload() -> None:
    """Import what the nodes will, and load their messages' type support (dlopen).

    Not rosidl's code generator, which every message module's package drags in and no node
    runs (a node that asks for it gets it then): 27 modules and ~6 MB the server would
    hold for each launch."""
    from robot_lab.rclpy_session import defer_code_generator

    os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')  # as the node scripts do
    defer_code_generator()
    for name in PRELOAD:
        importlib.import_module(name)
    for name, module in list(sys.modules.items()):
        if name.endswith(('.msg', '.srv', '.action')):
            for value in vars(module).values():
                loader = getattr(value, '__import_type_support__', None)
                if callable(loader) and isinstance(value, type):
                    loader()
    gc.collect()
    gc.freeze()  # the collector never touches (copies) these pages in a child


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    # Before preload starts LTTng's threads, which inherit the mask: a thread that did not
    # block these would take them with their default action.
    signals = SignalReader.open(RELAYED)
    if signals is None:  # no signalfd: ignore them, as a group's Ctrl-C must be
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    sock = socket.socket(fileno=int(args[0]))
    try:
        set_process_image(list(sys.orig_argv), dict(os.environ))  # the kernel allows it
        preload()
    except Exception as exc:  # the launcher execs every node instead
        sock.send(json.dumps({'error': f'{type(exc).__name__}: {exc}'}).encode())
        return 1
    _Server(sock, signals=signals).serve()
    return 0


if __name__ == '__main__':
    sys.exit(main())
