"""The kit's reads of /proc: a process's state and start time, its descriptors, its
mappings, its command line, who holds a socket. Each read tolerates a process that ends
meanwhile (OSError: the answer for a process that is gone)."""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterable

__all__ = ['cgroups', 'command_line', 'fd_targets', 'is_proc', 'mapped_paths', 'maps',
           'mount_points', 'net_namespace', 'own_socket_inodes', 'pid_namespace', 'pids',
           'process_running', 'socket_holders', 'start_time', 'stat_fields', 'status',
           'sysctl', 'thread_ids']


def _where(pid: int | None) -> str:
    return f'/proc/{"self" if pid is None else pid}'


def _stat_tail(pid: int | None) -> list[str]:
    """The fields of /proc/PID/stat after the command name (field 3, the state, first)."""
    with open(f'{_where(pid)}/stat', encoding='ascii', errors='replace') as stat:
        return stat.read().rpartition(')')[2].split()


def stat_fields(pid: int | None = None) -> list[int]:
    """/proc/PID/stat from field 3 on as numbers (the state letter: 0); OSError if gone."""
    return [int(x) if x.lstrip('-').isdigit() else 0 for x in _stat_tail(pid)]


def process_running(pid: int) -> bool:
    """True for a running process (a zombie, dead but not yet reaped, is not running)."""
    try:
        state = _stat_tail(pid)[0]
    except (OSError, IndexError):
        return False
    return state not in ('Z', 'X')


def start_time(pid: int) -> int | None:
    """The process's start time in clock ticks (tells a live pid from a reused one); None
    when it is gone or a zombie."""
    try:
        fields = _stat_tail(pid)
    except OSError:
        return None
    if not fields or fields[0] in ('Z', 'X'):
        return None
    return int(fields[19])


def pids() -> list[int]:
    """The pids of this PID namespace's processes (as /proc lists them)."""
    with contextlib.suppress(OSError):
        return [int(e.name) for e in os.scandir('/proc') if e.name.isdigit()]
    return []


def status(pid: int | None = None) -> dict[str, str]:
    """/proc/PID/status as field -> value (`Seccomp` -> `2`, `CapEff` -> hex); OSError if
    the process is gone."""
    with open(f'{_where(pid)}/status', encoding='utf-8', errors='replace') as file:
        return {key: value.strip() for key, _, value in
                (line.partition(':') for line in file) if value}


def sysctl(name: str) -> str | None:
    """A kernel setting by its sysctl name (`kernel.unprivileged_userns_clone`), None where
    this kernel has none."""
    try:
        with open('/proc/sys/' + name.replace('.', '/'), encoding='ascii') as file:
            return file.read().strip()
    except OSError:
        return None


def thread_ids(pid: int | None = None) -> list[int]:
    """The kernel's thread ids of the process (/proc/PID/task); OSError if gone."""
    return [int(name) for name in os.listdir(f'{_where(pid)}/task')]


def command_line(pid: int) -> list[str]:
    """The process's argv; OSError if gone or not readable."""
    with open(f'/proc/{pid}/cmdline', 'rb') as file:
        raw = file.read()
    return [os.fsdecode(part) for part in raw.split(b'\0')[:-1]] if raw else []


def fd_targets(pid: int | None = None) -> dict[int, str]:
    """Each open descriptor of the process -> what it points at (`socket:[INODE]`, a path);
    empty when the process is gone or another user's."""
    where = f'{_where(pid)}/fd'
    found: dict[int, str] = {}
    try:
        names = os.listdir(where)
    except OSError:
        return found
    for name in names:
        with contextlib.suppress(OSError, ValueError):  # closed meanwhile
            found[int(name)] = os.readlink(f'{where}/{name}')
    return found


def own_socket_inodes() -> set[int]:
    """The inodes of the sockets this process holds."""
    return {int(link[8:-1]) for link in fd_targets().values() if link.startswith('socket:[')}


def maps(pid: int | None = None) -> bytes:
    """/proc/PID/maps as bytes (a node's is ~110 KB and needs no decoding); OSError if gone."""
    with open(f'{_where(pid)}/maps', 'rb') as file:
        return file.read()


def mapped_paths(pid: int | None = None) -> list[str]:
    """The files mapped into the process, in order, each once."""
    seen: dict[str, None] = {}
    for line in maps(pid).decode(errors='replace').splitlines():
        parts = line.split(maxsplit=5)
        if len(parts) == 6 and parts[5].startswith('/'):
            seen.setdefault(parts[5], None)
    return list(seen)


def pid_namespace(pid: int | None = None) -> str:
    """The process's PID namespace (`pid:[INODE]`); OSError if gone or another user's."""
    return os.readlink(f'{_where(pid)}/ns/pid')


def net_namespace() -> str:
    """This process's network namespace (the inode number of /proc/self/ns/net), '' where
    it cannot be read: processes in two namespaces never hear each other's loopback."""
    try:
        return os.readlink('/proc/self/ns/net').partition('[')[2].rstrip(']')
    except OSError:
        return ''


def cgroups(pid: int | None = None) -> dict[str, str]:
    """The process's cgroup in each hierarchy (/proc/PID/cgroup): every v1 controller
    (`memory`, `pids`, ...) and v2's '' to its path; {} if it is gone."""
    found: dict[str, str] = {}
    with contextlib.suppress(OSError), open(f'{_where(pid)}/cgroup', encoding='utf-8') as file:
        for line in file:
            _id, controllers, where = line.rstrip('\n').split(':', 2)
            for controller in controllers.split(',') if controllers else ['']:
                found[controller] = where
    return found


def is_proc(path: str) -> bool:
    """Whether `path` is /proc or below it (a mount there is procfs's own)."""
    return path == '/proc' or path.startswith('/proc/')


def mount_points() -> list[str]:
    """This mount namespace's mount points, in mount order (/proc/self/mountinfo)."""
    points = []
    with open('/proc/self/mountinfo', encoding='utf-8', errors='surrogateescape') as file:
        for line in file:
            points.append(line.split()[4].encode().decode('unicode_escape'))  # '\040' -> ' '
    return points


_holders_lock = threading.Lock()
_holders: dict[frozenset[int], dict[int, frozenset[int]]] = {}


def socket_holders(inodes: Iterable[int]) -> dict[int, frozenset[int]]:
    """Socket inode -> the pids of the processes in this PID namespace that hold it (a
    child that inherited the socket holds it too), for each of these sockets that this
    user may trace; sockets held elsewhere are left out. Cached per set of sockets: a
    scan of /proc takes ~2 ms per 150 processes."""
    key = frozenset(inodes)
    with _holders_lock:
        if key in _holders:
            return _holders[key]
    wanted = {f'socket:[{inode}]': inode for inode in key}
    try:
        own_ns = pid_namespace()
    except OSError:
        return {}
    by_inode: dict[int, set[int]] = {}
    foreign: set[int] = set()
    for pid in pids():
        held = {wanted[link] for link in fd_targets(pid).values() if link in wanted}
        if not held:
            continue
        try:  # a process in another PID namespace writes its own view of its pid
            same = pid_namespace(pid) == own_ns
        except OSError:
            same = False
        for inode in held:
            if same:
                by_inode.setdefault(inode, set()).add(pid)
            else:
                foreign.add(inode)
    found = {inode: frozenset(held) for inode, held in by_inode.items() if inode not in foreign}
    with _holders_lock:
        if len(_holders) > 64:
            _holders.clear()
        _holders[key] = found
    return found
