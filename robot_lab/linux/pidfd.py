"""Process file descriptors: a handle on a process that a reused pid cannot fool, and
that select() reports readable when the process exits. Linux 5.3+ (pidfd_open), Python
3.9+; without them (or with `pidfd` switched off) callers poll."""

from __future__ import annotations

import contextlib
import os
import signal

from robot_lab.linux import capabilities

__all__ = ['open_pidfd', 'probe', 'send_signal']


def probe() -> str | None:
    """pidfd_open works on this process."""
    opener = getattr(os, 'pidfd_open', None)
    if opener is None:
        return 'os.pidfd_open missing (Python built without it)'
    try:
        fd = opener(os.getpid())
    except OSError as exc:
        return f'pidfd_open: {exc.strerror} (kernel before 5.3, or a seccomp filter)'
    os.close(fd)
    return None


def open_pidfd(pid: int) -> int | None:
    """A pidfd for `pid`, or None where pidfds are missing or switched off (the caller
    polls instead). ProcessLookupError if there is no such process."""
    if not capabilities.available('pidfd'):
        return None
    try:
        return os.pidfd_open(pid)
    except ProcessLookupError:
        raise
    except OSError:  # ENOSYS under a filter that the probe did not meet
        return None


def send_signal(pidfd: int, sig: int) -> None:
    """Signal the process behind `pidfd` (never another that took its pid)."""
    with contextlib.suppress(ProcessLookupError):
        signal.pidfd_send_signal(pidfd, sig)
