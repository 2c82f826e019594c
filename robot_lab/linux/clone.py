"""The fork server's fork: a child that is the launcher's, not the server's.

clone(CLONE_PARENT) makes the forked node a child of the server's parent (the launcher):
`ps`, psutil's children(), exit statuses and the parent-death signal are then exactly an
exec'd node's. What glibc's fork does besides the system call, `Forker.fork` does: the
child's tid in its thread descriptor (CLONE_CHILD_SETTID), Python's own before/after hooks
(PyOS_*Fork*, as os.fork calls them), LTTng-UST's fork hooks. pthread_atfork handlers do
not run; the server is single-threaded, so no lock they guard can be held.
"""

from __future__ import annotations

import ctypes
import os
import platform
import signal
import sys
import threading

from robot_lab.linux import procfs
from robot_lab.linux.libc import holding_gil, libc

__all__ = ['Forker', 'probe']

CLONE_PARENT = 0x00008000
CLONE_CHILD_SETTID = 0x01000000
SYS_CLONE = {'x86_64': 56, 'aarch64': 220}
_LTTNG_HOOKS = ('ust_before_fork', 'ust_after_fork_parent', 'ust_after_fork_child')


def probe() -> str | None:
    """This machine's clone and glibc are ones the fork server knows."""
    try:
        Forker()
    except OSError as exc:
        return str(exc)
    return None


def lttng_libraries() -> list[ctypes.CDLL]:
    """The LTTng-UST libraries loaded here (rcl's tracepoints): each runs two listener
    threads, and exports the hooks that make a fork safe and give the child its own."""
    libraries = []
    for path in procfs.mapped_paths():
        name = os.path.basename(path)
        if name.startswith('liblttng-ust') and not name.startswith(
                ('liblttng-ust-tracepoint', 'liblttng-ust-common', 'liblttng-ust-ctl')) \
                and '.so' in name:
            library = ctypes.CDLL(path)
            if all(hasattr(library, hook) for hook in _LTTNG_HOOKS):
                libraries.append(library)
    return libraries


def _tid_offset() -> int | None:
    """Where glibc keeps a thread's kernel tid in its `struct pthread` (pthread_self()):
    the one offset at which both this thread and a second one find their own tid."""
    library = libc()

    def offsets() -> set[int]:
        raw = ctypes.string_at(library.pthread_self(), 2048)
        tid = threading.get_native_id().to_bytes(4, sys.byteorder)
        return {at for at in range(0, len(raw), 4) if raw[at:at + 4] == tid}

    found = [offsets()]
    other = threading.Thread(target=lambda: found.append(offsets()))
    other.start()
    other.join()
    common = found[0] & found[-1] if len(found) == 2 else set()
    return common.pop() if len(common) == 1 else None


class Forker:
    """fork() whose child is the parent's parent's (see the module's docstring)."""

    def __init__(self) -> None:
        number = SYS_CLONE.get(platform.machine())
        offset = _tid_offset()
        if number is None or offset is None:
            raise OSError(f'cannot fork as the launcher on {platform.machine()} (glibc tid)')
        self.number = number
        self.tid = libc().pthread_self() + offset

    def fork(self) -> int:
        """The child's pid in the parent, 0 in the child (the launcher's child)."""
        libraries = lttng_libraries()  # loaded by the server's preload, after __init__
        masks = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t
        api = ctypes.pythonapi
        syscall = holding_gil().syscall
        api.PyOS_BeforeFork()
        for library, mask in zip(libraries, masks, strict=True):
            library.ust_before_fork(mask)
        flags = CLONE_PARENT | CLONE_CHILD_SETTID | signal.SIGCHLD
        # x86_64 takes (flags, stack, parent_tid, child_tid, tls); arm64 swaps the last two
        tail = (self.tid, 0) if self.number == SYS_CLONE['x86_64'] else (0, self.tid)
        args = (self.number, flags, 0, 0, *tail)
        pid = syscall(*(ctypes.c_long(arg) for arg in args))
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
