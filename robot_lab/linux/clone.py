"""The fork server's fork: a child that is the launcher's, not the server's.

clone(CLONE_PARENT) makes the forked node a child of the server's parent (the launcher):
`ps`, psutil's children(), exit statuses and the parent-death signal are then exactly an
exec'd node's. A plain os.fork() with the exit status sent over the server's socket
measured the same (issue 52: launch -> first Status 0.59 s against 0.67 s median of 10,
62 against 63-64 MB private), but its node is the server's child, so this route stays.

What glibc's fork does besides the system call, `Forker.fork` does, and nothing else runs
between Python's PyOS_BeforeFork and PyOS_AfterFork_* (where CPython itself runs only C;
3.13 holds the runtime's HEAD_LOCK there): only the two ctypes calls and the clone itself,
with the garbage collector off. Around that window: LTTng-UST's fork hooks (rcl's
tracepoints), the child's tid in its thread descriptor (CLONE_CHILD_SETTID), and the
child's robust-futex list registered again (set_robust_list, as glibc's child does: the
kernel gives a new task none). Not done: glibc's own pthread_atfork and malloc-arena
handlers, which only glibc can call; they guard against another thread holding a lock at
the fork, and the server forks only while its threads are the ones it started with
(`native_threads`: its own and LTTng's listeners, which wait in recvmsg and futexes).
"""

from __future__ import annotations

import ctypes
import gc
import os
import platform
import signal
import sys
import threading

from robot_lab.linux import procfs
from robot_lab.linux.libc import holding_gil, libc

__all__ = ['Forker', 'native_threads', 'probe']

CLONE_PARENT = 0x00008000
CLONE_CHILD_SETTID = 0x01000000
SYS_CLONE = {'x86_64': 56, 'aarch64': 220}
_SYS_ROBUST_LIST = {'x86_64': (274, 273), 'aarch64': (100, 99)}  # get_, set_robust_list
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


def native_threads() -> frozenset[int]:
    """The kernel's threads of this process (Python's and every library's)."""
    return frozenset(procfs.thread_ids())


class Forker:
    """fork() whose child is the parent's parent's (see the module's docstring)."""

    def __init__(self) -> None:
        machine = platform.machine()
        number = SYS_CLONE.get(machine)
        offset = _tid_offset()
        if number is None or offset is None:
            raise OSError(f'cannot fork as the launcher on {machine} (glibc tid)')
        self.number = number
        self.tid = libc().pthread_self() + offset
        self.robust = self._robust_list(machine)

    @staticmethod
    def _robust_list(machine: str) -> tuple[int, int, int] | None:
        """(set_robust_list's number, head, length) of this thread, as glibc registered
        them; None where the kernel gives none."""
        get, put = _SYS_ROBUST_LIST[machine]
        head, length = ctypes.c_void_p(), ctypes.c_size_t()
        if holding_gil().syscall(ctypes.c_long(get), ctypes.c_long(0), ctypes.byref(head),
                                 ctypes.byref(length)) != 0 or not head.value:
            return None
        return put, head.value, length.value

    def fork(self) -> int:
        """The child's pid in the parent, 0 in the child (the launcher's child)."""
        libraries = lttng_libraries()  # loaded by the server's preload, after __init__
        masks = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t
        api = ctypes.pythonapi
        syscall = holding_gil().syscall
        before, child, parent = api.PyOS_BeforeFork, api.PyOS_AfterFork_Child, \
            api.PyOS_AfterFork_Parent
        flags = CLONE_PARENT | CLONE_CHILD_SETTID | signal.SIGCHLD
        # x86_64 takes (flags, stack, parent_tid, child_tid, tls); arm64 swaps the last two
        tail = (self.tid, 0) if self.number == SYS_CLONE['x86_64'] else (0, self.tid)
        args = tuple(ctypes.c_long(arg) for arg in (self.number, flags, 0, 0, *tail))
        collecting = gc.isenabled()
        gc.disable()
        for library, mask in zip(libraries, masks, strict=True):
            library.ust_before_fork(mask)
        before()  # from here to child()/parent(): C only, as in os.fork
        pid = syscall(*args)
        child() if pid == 0 else parent()
        errno = ctypes.get_errno()
        if pid == 0 and self.robust is not None:
            number, head, length = self.robust
            syscall(ctypes.c_long(number), ctypes.c_void_p(head), ctypes.c_size_t(length))
        for library, mask in zip(reversed(libraries), reversed(masks), strict=True):
            (library.ust_after_fork_child if pid == 0 else library.ust_after_fork_parent)(mask)
        if collecting:
            gc.enable()
        if pid < 0:
            raise OSError(errno, f'clone: {os.strerror(errno)}')
        return int(pid)
