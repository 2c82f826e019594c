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
- is the launcher's child, not the server's (clone with CLONE_PARENT): `ps`, its parent
  pid, the launcher's wait for its exit status are an exec'd node's; and it dies with the
  launcher (PR_SET_PDEATHSIG, tied to the launcher's thread as an exec'd node's is): no
  node outlives its launcher, even after `kill -9`;
- exits as the interpreter would: the exit code of SystemExit, 1 after a traceback, or
  killed by SIGINT after an uncaught KeyboardInterrupt.

The server ignores SIGINT/SIGTERM (a terminal's Ctrl-C reaches the whole process group,
and the nodes must outlive it to shut down cleanly) and answers each request with the
node's pid; it exits when the launcher closes its socket. Run as
`python -m robot_lab.launch.fork_server FD`, FD a SOCK_SEQPACKET socket to the launcher
(robot_lab/launch/fork_client.py speaks to it).
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
import platform
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
_CLONE_PARENT = 0x00008000
_CLONE_CHILD_SETTID = 0x01000000
_SYS_CLONE = {'x86_64': 56, 'aarch64': 220}
_LIBC = ctypes.CDLL(None, use_errno=True)
_LIBC.sbrk.restype = ctypes.c_void_p
_LIBC_GIL = ctypes.PyDLL(None, use_errno=True)  # holds the GIL across the call, as os.fork
_LIBC_GIL.syscall.restype = ctypes.c_long
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


def _become(request: dict[str, Any], fds: list[int], launcher: int) -> None:
    """In the forked child (the launcher's): turn into the node the request describes, run
    it, exit."""
    code = 1
    try:
        _LIBC.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != launcher:
            os._exit(1)  # the launcher died before the parent-death signal was armed
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


def _tid_offset() -> int | None:
    """Where glibc keeps a thread's kernel tid in its `struct pthread` (pthread_self()):
    the one offset at which both this thread and a second one find their own tid."""
    _LIBC.pthread_self.restype = ctypes.c_void_p

    def offsets() -> set[int]:
        raw = ctypes.string_at(_LIBC.pthread_self(), 2048)
        tid = threading.get_native_id().to_bytes(4, sys.byteorder)
        return {at for at in range(0, len(raw), 4) if raw[at:at + 4] == tid}

    found = [offsets()]
    other = threading.Thread(target=lambda: found.append(offsets()))
    other.start()
    other.join()
    common = found[0] & found[-1] if len(found) == 2 else set()
    return common.pop() if len(common) == 1 else None


class _Forker:
    """fork() whose child is the launcher's, not the server's (clone with CLONE_PARENT):
    `ps`, psutil's children(), exit statuses and the parent-death signal are then exactly
    an exec'd node's. What glibc's fork does besides the system call, we do: the child's
    tid in its thread descriptor (CLONE_CHILD_SETTID), Python's own before/after hooks
    (PyOS_*Fork*, as os.fork calls them), LTTng-UST's fork hooks. pthread_atfork handlers
    do not run; the server is single-threaded, so no lock they guard can be held."""

    def __init__(self) -> None:
        number = _SYS_CLONE.get(platform.machine())
        offset = _tid_offset()
        if number is None or offset is None:
            raise OSError(f'cannot fork as the launcher on {platform.machine()} (glibc tid)')
        self.number = number
        self.tid = _LIBC.pthread_self() + offset

    def fork(self) -> int:
        libraries = _lttng_libraries()  # loaded by the preload, after __init__
        masks = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t
        api = ctypes.pythonapi
        api.PyOS_BeforeFork()
        for library, mask in zip(libraries, masks, strict=True):
            library.ust_before_fork(mask)
        flags = _CLONE_PARENT | _CLONE_CHILD_SETTID | signal.SIGCHLD
        # x86_64 takes (flags, stack, parent_tid, child_tid, tls); arm64 swaps the last two
        tail = (self.tid, 0) if self.number == _SYS_CLONE['x86_64'] else (0, self.tid)
        args = (self.number, flags, 0, 0, *tail)
        pid = _LIBC_GIL.syscall(*(ctypes.c_long(arg) for arg in args))
        errno = ctypes.get_errno()
        for library, mask in zip(reversed(libraries), reversed(masks), strict=True):
            (library.ust_after_fork_child if pid == 0 else library.ust_after_fork_parent)(mask)
        if pid == 0:
            api.PyOS_AfterFork_Child()
        else:
            api.PyOS_AfterFork_Parent()
        if pid < 0:
            raise OSError(errno, f'clone: {os.strerror(errno)}')
        return int(pid)


class _Server:
    def __init__(self, sock: socket.socket, forker: _Forker) -> None:
        self.sock = sock
        self.forker = forker

    def send(self, message: dict[str, Any]) -> None:
        self.sock.send(json.dumps(message).encode())

    def serve(self) -> None:
        self.send({'ready': os.getpid()})
        while self.request():
            pass

    def request(self) -> bool:
        """Fork one node; False once the launcher has closed its end."""
        data, fds, _, _ = socket.recv_fds(self.sock, MAX_MESSAGE, 4)
        if not data:
            return False
        try:
            request = json.loads(data)
            if threading.active_count() != 1:
                raise RuntimeError('the fork server has threads: forking it is unsafe')
            launcher = os.getppid()
            pid = self.forker.fork()
            if pid == 0:
                _become(request, fds, launcher)
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
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    sock = socket.socket(fileno=int(args[0]))
    try:
        set_process_image(list(sys.orig_argv), dict(os.environ))  # the kernel allows it
        forker = _Forker()
        preload()
    except Exception as exc:  # the launcher execs every node instead
        sock.send(json.dumps({'error': f'{type(exc).__name__}: {exc}'}).encode())
        return 1
    _Server(sock, forker).serve()
    return 0


if __name__ == '__main__':
    sys.exit(main())
