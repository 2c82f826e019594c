"""Signals read with their sender: signalfd(2).

A Python handler learns only which signal came, never from whom. The fork server needs the
sender: a signal one of its nodes sends its parent must reach the launcher, as it would
from an exec'd node, while a terminal's Ctrl-C to the whole process group must not reach
the launcher twice. signalfd gives each signal's sender pid; without it (not Linux, a
seccomp filter) `SignalReader.open` returns None and the caller keeps ignoring them.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import struct
from collections.abc import Iterable

from robot_lab.linux.libc import check, libc

__all__ = ['SignalReader']

_SIGINFO_SIZE = 128  # struct signalfd_siginfo
_SIGSET_BYTES = 128  # glibc's sigset_t
_SFD_CLOEXEC = os.O_CLOEXEC
_SFD_NONBLOCK = os.O_NONBLOCK


class SignalReader:
    """Blocks `signals` in this thread (and every thread it starts later) and reads them,
    with their sender, from a descriptor select() reports readable."""

    def __init__(self, fd: int, signals: frozenset[int]) -> None:
        self.fd = fd
        self.signals = signals

    @classmethod
    def open(cls, signals: Iterable[int]) -> SignalReader | None:
        """Block `signals` and open their signalfd; None (nothing blocked) where the kernel
        or the C library has none. Call it before starting threads: a thread that does not
        block a signal may take it with its default action."""
        wanted = frozenset(int(s) for s in signals)
        mask = bytearray(_SIGSET_BYTES)
        for signum in wanted:
            mask[(signum - 1) // 8] |= 1 << ((signum - 1) % 8)
        buffer = (ctypes.c_ubyte * _SIGSET_BYTES).from_buffer(mask)
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, wanted)
        try:
            fd = check(libc().signalfd(-1, ctypes.byref(buffer),
                                       _SFD_CLOEXEC | _SFD_NONBLOCK), 'signalfd')
        except (OSError, AttributeError):
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
            return None
        return cls(fd, wanted)

    def fileno(self) -> int:
        return self.fd

    def read(self) -> list[tuple[int, int]]:
        """The signals pending now, each as (signal number, sender pid; 0 from the kernel,
        e.g. a terminal's Ctrl-C)."""
        taken: list[tuple[int, int]] = []
        while True:
            try:
                data = os.read(self.fd, _SIGINFO_SIZE * 16)
            except BlockingIOError:
                return taken
            for offset in range(0, len(data) - _SIGINFO_SIZE + 1, _SIGINFO_SIZE):
                signum, _errno, code, pid = struct.unpack_from('IiiI', data, offset)
                # SI_USER (0), SI_QUEUE (-1), SI_TKILL (-6) carry a sender; others are the
                # kernel's own (a terminal's keys: SI_KERNEL).
                taken.append((signum, pid if code in (0, -1, -6) else 0))

    def close(self) -> None:
        with contextlib.suppress(OSError):
            os.close(self.fd)
