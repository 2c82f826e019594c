"""Fast DDS's shared-memory segments that a killed participant leaves in /dev/shm.

Every participant maps a segment of its own (`/dev/shm/fastrtps_<16 hex>`, 540 KB here)
and holds an exclusive lock on its `_el` file while it lives. A clean exit removes both; a
participant killed with SIGKILL (a node whose kernel or launcher was killed, a node that
ignored SIGINT and SIGTERM) leaves them, and /dev/shm is memory. On a hub that restarts
kernels all term, that adds up (this workstation held 659 of them, 364 MB, after one
session's test runs). Fast DDS's own `fastdds shm clean` removes them when asked; the kit
asks where its own participants have just gone: a launch that ended, a lesson's set-up.

A segment is dead when nobody holds its lock. One younger than `min_age` is left alone: a
participant creates the lock file an instant before it takes the lock, and a busy host can
hold it between the two. Ports (`fastrtps_port*`) are left to Fast DDS, which takes over a
dead port itself when it opens it again.
"""

from __future__ import annotations

import fcntl
import os
import re
import time
from dataclasses import dataclass
from pathlib import Path

__all__ = ['SHM_DIR', 'Swept', 'sweep_dead_segments']

SHM_DIR = Path('/dev/shm')
_SEGMENT_LOCK = re.compile(r'fastrtps_[0-9a-f]{16}_el')


@dataclass
class Swept:
    """What one sweep removed: dead segments and the bytes of memory they held."""

    segments: int = 0
    bytes: int = 0


def _take_lock(lock: Path) -> int | None:
    """An fd holding `lock` when nobody else did (its participant is gone), else None."""
    try:
        fd = os.open(lock, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:  # held: its participant lives
        os.close(fd)
        return None
    return fd


def sweep_dead_segments(shm_dir: Path = SHM_DIR, min_age: float = 10.0) -> Swept:
    """Remove this user's segments whose participant is gone (see the module's docstring)."""
    swept = Swept()
    try:
        names = os.listdir(shm_dir)
    except OSError:
        return swept
    uid, now = os.getuid(), time.time()
    for name in names:
        if not _SEGMENT_LOCK.fullmatch(name):
            continue
        lock = shm_dir / name
        try:
            info = lock.stat()
        except OSError:
            continue
        if info.st_uid != uid or now - info.st_mtime < min_age:
            continue
        fd = _take_lock(lock)
        if fd is None:
            continue
        try:  # removed while this process holds the lock: no other sweep races it
            segment = shm_dir / name[:-3]
            try:
                swept.bytes += segment.stat().st_blocks * 512
                segment.unlink()
            except FileNotFoundError:
                pass
            lock.unlink(missing_ok=True)
            swept.segments += 1
        except OSError:
            continue
        finally:
            os.close(fd)
    return swept
