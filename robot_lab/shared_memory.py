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

A live participant's port can be taken over too, which leaves it deaf (`lost_ports`). The
kit's profile sends its participants' data by UDP, so they listen on no port; a process run
with a profile of the user's own (or none) still does, and is still named here.
"""

from __future__ import annotations

import fcntl
import os
import re
import time
from dataclasses import dataclass
from pathlib import Path

from robot_lab.domain import domain_ports
from robot_lab.linux.procfs import fd_targets, maps

__all__ = ['HEARING_CHECK', 'SHM_DIR', 'Swept', 'deaf_note', 'deaf_processes', 'listening_ports',
           'lost_ports', 'sweep_dead_segments']

SHM_DIR = Path('/dev/shm')
# How often a long-lived process of the kit (the graph daemon, a launcher for its nodes)
# checks for `lost_ports`: 0.16 ms for a process that listens on no port (its /proc fds;
# the kit's own, measured idle), about 2 ms on a loaded host for one that does (its /proc
# maps too, ~110 KB for a node), so at most 0.12 % of a core for a launch of three nodes,
# and a stale graph or a node that hears no newcomer is named within seconds.
HEARING_CHECK = 5.0
_SEGMENT_LOCK = re.compile(r'fastrtps_[0-9a-f]{16}_el')
_PORT_LOCK = re.compile(r'/dev/shm/fastrtps_port(\d+)_el')
_REMOVED_PORT = re.compile(rb'/dev/shm/fastrtps_port(\d+) \(deleted\)$', re.M)


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


def lost_ports(pid: int | None = None, listening: set[int] | None = None) -> list[int]:
    """The shared-memory ports process `pid` (default: this one) listens on whose file
    another process removed: ports on which it no longer hears anyone new.

    Each participant listens on ports of its own (`/dev/shm/fastrtps_port<N>`; it holds the
    lock of `..._el` while it lives). Fast DDS replaces a port file it judges dead (an owner
    that misses its one-second health check, a port mutex held for two seconds: a crowded
    host can look so; Fast DDS issues 5737, 6117). Participants that open the port after
    that send into a file nobody reads, so the owner never hears them: in one CI run a
    test's session missed every node started after it for a minute, and each new
    participant logged `Failed init_port fastrtps_port7006: open_and_lock_file failed`.
    rmw_fastrtps adds the transport itself under ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST;
    the kit's profile only keeps data off it. The owner still maps the removed file: /proc/PID/maps
    shows it `(deleted)`. `listening`: its `listening_ports`, when the caller has them.
    """
    if not (listening := listening_ports(pid) if listening is None else listening):
        return []  # the kit's participants: their data comes by UDP
    try:
        # bytes: a node's maps are about 110 KB, and need no decoding
        removed = {int(n) for n in _REMOVED_PORT.findall(maps(pid))}
    except OSError:  # gone, or not ours
        return []
    return sorted(removed & listening)


def listening_ports(pid: int | None = None) -> set[int]:
    """The shared-memory ports process `pid` (default: this one) listens on: those whose
    `_el` lock file it holds open."""
    ports: set[int] = set()
    for target in fd_targets(pid).values():
        if (match := _PORT_LOCK.fullmatch(target)) is not None:
            ports.add(int(match[1]))
    return ports


def deaf_note(pid: int | None = None) -> str:
    """A sentence for an error about the graph when `lost_ports(pid)` found any, else ''."""
    ports = lost_ports(pid)
    if not ports:
        return ''
    listed = ', '.join(str(port) for port in ports)
    return (f'this process no longer hears ROS participants started after Fast DDS took over '
            f'its shared-memory port {listed} (a crowded host): restart it (in a notebook: '
            f'Kernel > Restart Kernel)')


def deaf_processes(domain: int) -> list[tuple[int, str, list[int]]]:
    """This user's processes of ROS domain `domain` with `lost_ports`: (pid, command line,
    ports), for the doctor. A process's domain is read from the ports it listens on (Fast
    DDS numbers each domain's ports apart; its environment may not say: a kernel sets
    ROS_DOMAIN_ID after it started)."""
    import psutil

    ports = domain_ports(domain)
    found = []
    for proc in psutil.process_iter(['uids', 'cmdline']):
        uids = proc.info['uids']
        if uids is None or uids.effective != os.getuid():
            continue
        listening = listening_ports(proc.pid)
        if listening.isdisjoint(ports):
            continue  # another domain's, or no participant at all
        if lost := lost_ports(proc.pid, listening):
            found.append((proc.pid, ' '.join(proc.info['cmdline'] or []), lost))
    return found
