"""What a process costs a host in memory: RSS, the private part (USS), and a group's own.

RSS counts every page a process maps, including the venv's shared libraries (rclpy, Fast
DDS, numpy) that one more student does not add again; USS (Private_Clean + Private_Dirty
from /proc/PID/smaps_rollup) is what one more such process adds. Processes forked from one
parent (the launcher's fork server) share pages with each other that no other student
maps: those are in no process's USS, yet one more student adds them. `group_private_mb`
counts them (pages mapped only by the group, from /proc/PID/pagemap and /proc/kpagecount,
which need root; None otherwise). Shared by the benches.
"""

from __future__ import annotations

import collections
import os
import struct
from collections.abc import Iterable
from pathlib import Path

import psutil

__all__ = ['group_private_mb', 'private_mb', 'tree_memory']

_PAGE = os.sysconf('SC_PAGE_SIZE')
_PRESENT = 1 << 63
_FILE_OR_SHARED = 1 << 61
_PFN_MASK = (1 << 55) - 1


def private_mb(pid: int) -> float:
    """USS of one process in MB (0.0 if it is gone or unreadable)."""
    kb = 0
    try:
        for line in Path(f'/proc/{pid}/smaps_rollup').read_text().splitlines():
            if line.startswith(('Private_Clean:', 'Private_Dirty:')):
                kb += int(line.split()[1])
    except (OSError, ValueError):
        return 0.0
    return kb / 1024


def _frames(pid: int) -> collections.Counter[int]:
    """Anonymous frame -> how many times `pid` maps it (resident pages only; no file
    pages: a library's pages are shared with every other student's processes)."""
    frames: collections.Counter[int] = collections.Counter()
    ranges = []
    for line in Path(f'/proc/{pid}/maps').read_text().splitlines():
        start, end = (int(x, 16) for x in line.split()[0].split('-'))
        ranges.append((start, end))
    fd = os.open(f'/proc/{pid}/pagemap', os.O_RDONLY)
    try:
        for start, end in ranges:
            count = (end - start) // _PAGE
            data = os.pread(fd, count * 8, start // _PAGE * 8)
            for (entry,) in struct.iter_unpack('<Q', data):
                if entry & _PRESENT and not entry & _FILE_OR_SHARED and entry & _PFN_MASK:
                    frames[entry & _PFN_MASK] += 1
    finally:
        os.close(fd)
    return frames


def group_private_mb(pids: Iterable[int]) -> float | None:
    """MB of the anonymous pages that these processes map and no other process does: what
    one more such group (a student's launch) adds to a host, pages its processes share
    with each other included. None without root (no frame numbers)."""
    if os.geteuid() != 0:
        return None
    inside: collections.Counter[int] = collections.Counter()
    try:
        for pid in pids:
            inside.update(_frames(pid))
    except (OSError, ValueError):
        return None
    own = 0
    fd = os.open('/proc/kpagecount', os.O_RDONLY)
    try:
        for frame, mapped in inside.items():
            (total,) = struct.unpack('<Q', os.pread(fd, 8, frame * 8))
            own += total <= mapped
    finally:
        os.close(fd)
    return own * _PAGE / 2**20


def tree_memory(pid: int) -> tuple[float, float, list[tuple[str, float, float]]]:
    """(RSS MB, USS MB) of a process and its descendants, and (command, RSS, USS) of each."""
    rows = []
    root = psutil.Process(pid)
    for proc in [root, *root.children(recursive=True)]:
        try:
            cmd = ' '.join(proc.cmdline()[:4])
            rows.append((cmd, proc.memory_info().rss / 2**20, private_mb(proc.pid)))
        except psutil.Error:
            continue
    return sum(r for _, r, _ in rows), sum(u for _, _, u in rows), rows
