"""prctl(2): the parent-death signal, the thread's name, no_new_privs, dumpable, and the
process image (/proc/PID/cmdline and environ) a forked node shows."""

from __future__ import annotations

import ctypes
import os
import signal
from collections.abc import Mapping, Sequence
from typing import Any

from robot_lab.linux import capabilities, procfs
from robot_lab.linux.libc import check, libc, loaded

__all__ = ['PR_SET_DUMPABLE', 'PR_SET_NAME', 'PR_SET_NO_NEW_PRIVS', 'PR_SET_PDEATHSIG', 'probe',
           'process_image_probe', 'set_dumpable', 'set_name', 'set_no_new_privs',
           'set_parent_death_signal', 'set_process_image']

PR_SET_PDEATHSIG = 1
PR_SET_DUMPABLE = 4
PR_SET_NAME = 15
PR_SET_MM = 35
PR_SET_MM_MAP = 14
PR_SET_MM_MAP_SIZE = 15
PR_SET_NO_NEW_PRIVS = 38
_KEEP: list[Any] = []  # a process image's argv/environ block lives as long as the process


def probe() -> str | None:
    """prctl is there (the C library loads and knows it)."""
    libc().prctl  # noqa: B018  # AttributeError: no prctl in this C library
    return None


def set_parent_death_signal(sig: int = signal.SIGKILL) -> bool:
    """Ask for `sig` when the thread that forked this process ends; False when this machine
    cannot (or `parent_death` is switched off). Safe between fork and exec: it takes no
    lock, and uses the C library only if the parent loaded it (see `libc.loaded`)."""
    library = loaded()
    if library is None or capabilities.disabled('parent_death'):
        return False
    return bool(library.prctl(PR_SET_PDEATHSIG, sig, 0, 0, 0) == 0)


def set_name(name: str) -> None:
    """This thread's name (`ps`, /proc/PID/comm), cut to 15 bytes as exec does."""
    libc().prctl(PR_SET_NAME, os.fsencode(name)[:15], 0, 0, 0)


def set_no_new_privs() -> None:
    """No exec here may gain privileges again (set-uid, file capabilities)."""
    check(libc().prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), 'prctl(PR_SET_NO_NEW_PRIVS)')


def set_dumpable(dumpable: bool) -> None:
    """Not dumpable: no core file, and /proc/PID/mem, fds and ptrace out of reach of
    processes of the same uid."""
    check(libc().prctl(PR_SET_DUMPABLE, int(dumpable), 0, 0, 0), 'prctl(PR_SET_DUMPABLE)')


class _MmMap(ctypes.Structure):
    """struct prctl_mm_map (linux/prctl.h)."""

    _fields_ = [(name, ctypes.c_uint64) for name in (
        'start_code', 'end_code', 'start_data', 'end_data', 'start_brk', 'brk',
        'start_stack', 'arg_start', 'arg_end', 'env_start', 'env_end', 'auxv')] + [
        ('auxv_size', ctypes.c_uint32), ('exe_fd', ctypes.c_uint32)]


def _block(parts: Sequence[str]) -> bytes:
    return b''.join(os.fsencode(p) + b'\0' for p in parts)


def process_image_probe() -> str | None:
    """The kernel lets a process set its own image (asks only for struct prctl_mm_map's
    size, changing nothing)."""
    size = ctypes.c_uint()
    if libc().prctl(PR_SET_MM, PR_SET_MM_MAP_SIZE, ctypes.byref(size), 0, 0) != 0:
        return (f'prctl(PR_SET_MM_MAP): {os.strerror(ctypes.get_errno())} (a kernel '
                'without CONFIG_CHECKPOINT_RESTORE)')
    if size.value != ctypes.sizeof(_MmMap):
        return f'prctl(PR_SET_MM_MAP): a struct of {size.value} bytes, not {ctypes.sizeof(_MmMap)}'
    return None


def set_process_image(cmdline: Sequence[str], environ: Mapping[str, str]) -> None:
    """Make /proc/self/cmdline and environ show these (the kernel reads them from the
    addresses given here; no privilege needed); OSError if the kernel refuses."""
    library = libc()
    args, env = _block(cmdline), _block([f'{k}={v}' for k, v in environ.items()])
    buffer = ctypes.create_string_buffer(args + env, len(args) + len(env))
    _KEEP.append(buffer)
    base = ctypes.addressof(buffer)
    field = procfs.stat_fields()
    # man 5 proc: field N is field[N - 3] once pid and comm are cut off.
    mm = _MmMap(start_code=field[23], end_code=field[24], start_stack=field[25],
                start_data=field[42], end_data=field[43], start_brk=field[44],
                arg_start=base, arg_end=base + len(args),
                env_start=base + len(args), env_end=base + len(args) + len(env),
                auxv=0, auxv_size=0, exe_fd=0xFFFFFFFF)
    mm.brk = library.sbrk(0)  # last: malloc must not move it before the call
    check(library.prctl(PR_SET_MM, PR_SET_MM_MAP, ctypes.byref(mm), ctypes.sizeof(mm), 0),
          'prctl(PR_SET_MM_MAP)')
