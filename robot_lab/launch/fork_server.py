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

The server ignores SIGINT/SIGTERM (a terminal's Ctrl-C reaches the whole process group,
and the nodes must outlive it to shut down cleanly), reaps its children and reports each
exit status to the launcher. Run as `python -m robot_lab.launch.fork_server FD`, FD a
SOCK_SEQPACKET socket to the launcher (robot_lab/launch/fork_client.py speaks to it).
"""

from __future__ import annotations

import builtins
import contextlib
import ctypes
import gc
import importlib
import io
import json
import os
import selectors
import signal
import socket
import sys
import threading
import traceback
import types
from collections.abc import Sequence
from importlib.machinery import SourceFileLoader
from types import TracebackType
from typing import Any

__all__ = ['PRELOAD', 'main']

# What the kit's node scripts import (kept in step with robot_lab/nodes/).
PRELOAD = (
    'rclpy', 'rclpy.node', 'rclpy.executors', 'rclpy.signals', 'rclpy.parameter',
    'rclpy.action', 'std_msgs.msg', 'geometry_msgs.msg', 'rcl_interfaces.msg',
    'robot_lab.nodes.base', 'robot_lab.nodes.sensor_node', 'robot_lab.nodes.controller_node',
    'robot_lab.nodes.robot_node',
)
MAX_MESSAGE = 1 << 20
_PR_SET_PDEATHSIG = 1
_PR_SET_NAME = 15
_PR_SET_MM = 35
_PR_SET_MM_MAP = 14
_LIBC = ctypes.CDLL(None, use_errno=True)
_LIBC.sbrk.restype = ctypes.c_void_p
_KEEP: list[Any] = []  # the child's new argv/environ block must live as long as it does


class _MmMap(ctypes.Structure):
    """struct prctl_mm_map (linux/prctl.h)."""

    _fields_ = [(name, ctypes.c_uint64) for name in (
        'start_code', 'end_code', 'start_data', 'end_data', 'start_brk', 'brk',
        'start_stack', 'arg_start', 'arg_end', 'env_start', 'env_end', 'auxv')] + [
        ('auxv_size', ctypes.c_uint32), ('exe_fd', ctypes.c_uint32)]


def _block(parts: Sequence[str]) -> bytes:
    return b''.join(os.fsencode(p) + b'\0' for p in parts)


def set_process_image(cmdline: Sequence[str], environ: dict[str, str]) -> None:
    """Make /proc/self/cmdline and environ show these (the kernel reads them from the
    addresses given here); raises OSError if the kernel refuses."""
    args, env = _block(cmdline), _block([f'{k}={v}' for k, v in environ.items()])
    buffer = ctypes.create_string_buffer(args + env, len(args) + len(env))
    _KEEP.append(buffer)
    base = ctypes.addressof(buffer)
    stat = open('/proc/self/stat').read().rsplit(')', 1)[1].split()  # noqa: SIM115
    field = [int(x) if x.lstrip('-').isdigit() else 0 for x in stat]
    # man 5 proc: field N is field[N - 3] once pid and comm are cut off.
    mm = _MmMap(start_code=field[23], end_code=field[24], start_stack=field[25],
                start_data=field[42], end_data=field[43], start_brk=field[44],
                arg_start=base, arg_end=base + len(args),
                env_start=base + len(args), env_end=base + len(args) + len(env),
                auxv=0, auxv_size=0, exe_fd=0xFFFFFFFF)
    mm.brk = _LIBC.sbrk(0)  # last: malloc must not move it before the call
    if _LIBC.prctl(_PR_SET_MM, _PR_SET_MM_MAP, ctypes.byref(mm), ctypes.sizeof(mm), 0):
        errno = ctypes.get_errno()
        raise OSError(errno, f'prctl(PR_SET_MM_MAP): {os.strerror(errno)}')


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
        _LIBC.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != server:
            os._exit(1)  # the server died before the parent-death signal was armed
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
        os.closerange(3, os.sysconf('SC_OPEN_MAX'))
        signal.set_wakeup_fd(-1)
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
        _LIBC.prctl(_PR_SET_NAME, os.fsencode(os.path.basename(script))[:15], 0, 0, 0)
        code = _run_script(request['cmdline'], script, argv)
    except BaseException:  # never return into the server's loop
        traceback.print_exc()
    finally:
        os._exit(code)


def _lttng_libraries() -> list[ctypes.CDLL]:
    """The LTTng-UST libraries loaded here (rcl's tracepoints): each runs two listener
    threads, and exports the hooks that make a fork safe and give the child its own."""
    found = []
    with open('/proc/self/maps') as maps:
        for line in maps:
            path = line.split()[-1]
            name = os.path.basename(path)
            if name.startswith('liblttng-ust') and not name.startswith(
                    ('liblttng-ust-tracepoint', 'liblttng-ust-common', 'liblttng-ust-ctl')) \
                    and '.so' in name and path not in found:
                found.append(path)
    libraries = []
    for path in found:
        library = ctypes.CDLL(path)
        if all(hasattr(library, hook) for hook in
               ('ust_before_fork', 'ust_after_fork_parent', 'ust_after_fork_child')):
            libraries.append(library)
    return libraries


def _fork() -> int:
    """os.fork() wrapped in LTTng-UST's fork hooks, as liblttng-ust-fork.so would: its
    locks are not held across the fork, and the child starts its own listener threads,
    as an exec'd node has them."""
    libraries = _lttng_libraries()
    saved = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t
    for library, mask in zip(libraries, saved, strict=True):
        library.ust_before_fork(mask)
    pid = os.fork()
    for library, mask in zip(reversed(libraries), reversed(saved), strict=True):
        (library.ust_after_fork_child if pid == 0 else library.ust_after_fork_parent)(mask)
    return pid


class _Server:
    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.children: set[int] = set()
        self.selector = selectors.DefaultSelector()
        self.wake_r, wake_w = os.pipe()
        os.set_blocking(self.wake_r, False)
        os.set_blocking(wake_w, False)
        signal.set_wakeup_fd(wake_w)
        signal.signal(signal.SIGCHLD, lambda signum, frame: None)
        self.selector.register(self.wake_r, selectors.EVENT_READ, 'child')
        self.selector.register(sock, selectors.EVENT_READ, 'request')

    def send(self, message: dict[str, Any], fds: Sequence[int] = ()) -> None:
        socket.send_fds(self.sock, [json.dumps(message).encode()], list(fds))

    def serve(self) -> None:
        self.send({'ready': os.getpid()})
        while True:
            for key, _ in self.selector.select():
                if key.data == 'child':
                    self.reap()
                elif not self.request():
                    self.close()
                    return

    def request(self) -> bool:
        data, fds, _, _ = socket.recv_fds(self.sock, MAX_MESSAGE, 4)
        if not data:
            return False
        try:
            request = json.loads(data)
            if threading.active_count() != 1:
                raise RuntimeError('the fork server has threads: forking it is unsafe')
            server = os.getpid()
            pid = _fork()
            if pid == 0:
                _become(request, fds, server)
            self.children.add(pid)
            pidfd = os.pidfd_open(pid)
            try:
                self.send({'pid': pid}, [pidfd])
            finally:
                os.close(pidfd)
        except Exception as exc:  # the launcher execs the node instead
            self.send({'error': f'{type(exc).__name__}: {exc}'})
        finally:
            for fd in fds:
                os.close(fd)
        return True

    def reap(self) -> None:
        try:
            while os.read(self.wake_r, 4096):
                pass
        except BlockingIOError:
            pass
        while self.children:
            pid, status = os.waitpid(-1, os.WNOHANG)
            if pid == 0:
                return
            self.children.discard(pid)
            self.send({'exit': pid, 'status': status})

    def close(self) -> None:
        """The launcher is gone or done: no child may outlive it."""
        for pid in self.children:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        for pid in list(self.children):
            os.waitpid(pid, 0)


def preload() -> None:
    """Import what the nodes will, and load their messages' type support (dlopen)."""
    os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')  # as the node scripts do
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
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    sock = socket.socket(fileno=int(args[0]))
    try:
        set_process_image(list(sys.orig_argv), dict(os.environ))  # the kernel allows it
        preload()
    except Exception as exc:  # the launcher execs every node instead
        sock.sendmsg([json.dumps({'error': f'{type(exc).__name__}: {exc}'}).encode()])
        return 1
    _Server(sock).serve()
    return 0


if __name__ == '__main__':
    sys.exit(main())
