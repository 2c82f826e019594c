"""The C library, loaded once per process (thread-safe), and errno turned into OSError.

Loaded before any fork: a child between fork and exec (`process.child_setup`) must find
it loaded, since it may take no lock another thread held at the fork.
"""

from __future__ import annotations

import ctypes
import os
import threading

__all__ = ['check', 'libc', 'load_global', 'loaded']

_lock = threading.Lock()
_libc: ctypes.CDLL | None = None
_failed: OSError | None = None


def _load() -> None:
    global _libc, _failed
    with _lock:
        if _libc is not None or _failed is not None:
            return
        try:
            if os.name != 'posix':
                raise OSError('no C library of the kind the kit needs (not Linux)')
            name = 'libc.so.6'  # glibc's soname: no ldconfig run (ctypes.util) to find it
            try:
                library = ctypes.CDLL(name, use_errno=True)
            except OSError:
                from ctypes.util import find_library

                name = find_library('c') or name
                library = ctypes.CDLL(name, use_errno=True)
            library.sbrk.restype = ctypes.c_void_p
        except (OSError, AttributeError) as exc:
            _failed = OSError(f'cannot load the C library: {exc}')
            return
        _libc = library


def libc() -> ctypes.CDLL:
    """The C library (calls release the GIL); OSError where there is none to load."""
    if _libc is None:
        _load()
        if _libc is None:
            raise _failed or OSError('no C library')
    return _libc


def loaded() -> ctypes.CDLL | None:
    """The C library if it is loaded already, else None, taking no lock: for code between
    fork and exec."""
    return _libc


def check(result: int, what: str) -> int:
    """`result` of a libc call that sets errno on -1 (or any negative): OSError naming
    `what` and the error, else `result`."""
    if result < 0:
        errno = ctypes.get_errno()
        raise OSError(errno, f'{what}: {os.strerror(errno)}')
    return result


def load_global(path: str | os.PathLike[str]) -> None:
    """dlopen `path` with RTLD_GLOBAL: later libraries find its symbols by name, as if it
    had been on LD_LIBRARY_PATH when the process started; OSError if it cannot load."""
    ctypes.CDLL(os.fspath(path), mode=ctypes.RTLD_GLOBAL)
