"""What a process costs a host in memory: RSS, and the private part (USS).

RSS counts every page a process maps, including the venv's shared libraries (rclpy, Fast
DDS, numpy) that one more student does not add again; USS (Private_Clean + Private_Dirty
from /proc/PID/smaps_rollup) is what one more such process adds. Shared by the benches.
"""

from __future__ import annotations

from pathlib import Path

import psutil

__all__ = ['private_mb', 'tree_memory']


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
