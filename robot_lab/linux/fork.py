"""The fork server's fork: os.fork(), with LTTng-UST's fork hooks around it.

Issue 52 measured a plain os.fork() (exit statuses sent over the server's socket) against a
clone(CLONE_PARENT) made through ctypes that made each node the launcher's own child:
launch -> first Status 0.59 s against 0.67 s (median of 10), 62 against 63-64 MB private.
The plain fork stays: CPython's own fork runs only C between PyOS_BeforeFork and
PyOS_AfterFork_*, and glibc's fork does the rest (pthread_atfork handlers, malloc's arenas,
the robust-futex list, the child's tid).

rcl loads LTTng-UST (its tracepoints), whose two listener threads take locks of its own;
the library exports the hooks its preloadable fork wrapper (liblttng-ust-fork) calls, and
`fork` calls them too: no lock of theirs is held across the fork, and the child gets its
own listeners, as an exec'd node has. The server forks only while its threads are the ones
it started with (`native_threads`: its own and LTTng's, which wait in recvmsg and futexes).
"""

from __future__ import annotations

import ctypes
import os
import warnings

from robot_lab.linux import prctl, procfs

__all__ = ['fork', 'native_threads', 'probe']

_LTTNG_HOOKS = ('ust_before_fork', 'ust_after_fork_parent', 'ust_after_fork_child')


def probe() -> str | None:
    """A forked node can take its own command line and environment (PR_SET_MM_MAP: a
    kernel built with CONFIG_CHECKPOINT_RESTORE, as every major distribution's is)."""
    return prctl.process_image_probe()


_lttng: list[ctypes.CDLL] = []  # once found, kept: our handles keep them loaded


def lttng_libraries() -> list[ctypes.CDLL]:
    """The LTTng-UST libraries loaded here that export the fork hooks. Kept once found: the
    scan of this process's mappings took 2.3 ms (median of 50, rclpy imported), at every
    fork. Looked for again while none is found, as rcl loads LTTng only when imported."""
    global _lttng
    if _lttng:
        return _lttng
    libraries = []
    for path in procfs.mapped_paths():
        name = os.path.basename(path)
        if name.startswith('liblttng-ust') and not name.startswith(
                ('liblttng-ust-tracepoint', 'liblttng-ust-common', 'liblttng-ust-ctl')) \
                and '.so' in name:
            library = ctypes.CDLL(path)
            if all(hasattr(library, hook) for hook in _LTTNG_HOOKS):
                libraries.append(library)
    _lttng = libraries
    return libraries


def native_threads() -> frozenset[int]:
    """The kernel's threads of this process (Python's and every library's)."""
    return frozenset(procfs.thread_ids())


def fork() -> int:
    """os.fork() between LTTng-UST's before/after hooks: the child's pid, 0 in the child."""
    libraries = lttng_libraries()  # loaded by the server's preload
    masks = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t
    for library, mask in zip(libraries, masks, strict=True):
        library.ust_before_fork(mask)
    pid = -1
    try:
        with warnings.catch_warnings():  # 3.12+ warns of LTTng's threads, which are safe
            warnings.simplefilter('ignore', DeprecationWarning)
            pid = os.fork()
    finally:
        for library, mask in zip(reversed(libraries), reversed(masks), strict=True):
            (library.ust_after_fork_child if pid == 0 else library.ust_after_fork_parent)(mask)
    return pid
