"""What a grading job may see and who it is: a read-only machine, its own folder, no one's
privileges.

Run by `sandbox.enter()` first thing in the job, inside its new mount, PID, network and
IPC namespaces (and a user namespace when the grader is not root), before any student
code: every mount becomes read-only; `/tmp`, `/var/tmp` and `/dev/shm` are fresh private
tmpfs; every top-level folder that is not the system's (`/home`, `/root`, `/work`, `/run`,
`/mnt`, …) is covered by an empty read-only tmpfs, with only what the job needs bound back
read-only (the venv, the Python it runs on, the kit's package); the job folder is bound back
writable at its own path. So the job cannot read or write other students' hand-ins, the
instructor's home or the output folder. Then the job gives up its privileges: as root it
becomes an unprivileged uid with no capabilities (the grader chowned the job folder to it);
otherwise it enters one more user namespace, where it holds no capability over its mounts.
`no_new_privs` keeps set-uid programs from giving any back.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import re
import sys
from collections.abc import Iterable
from pathlib import Path

__all__ = ['SYSTEM_DIRS', 'blocked_attempts', 'confine', 'drop_privileges', 'job_uid',
           'leftover_processes']

# Top-level folders a job sees (read-only); every other one is hidden.
SYSTEM_DIRS = frozenset({'bin', 'sbin', 'lib', 'lib32', 'lib64', 'libx32', 'usr', 'etc',
                         'opt', 'var', 'proc', 'sys', 'dev', 'tmp'})
PRIVATE_TMP = ('/tmp', '/var/tmp', '/dev/shm')
_MS_RDONLY, _MS_NOSUID, _MS_NODEV, _MS_NOEXEC = 1, 2, 4, 8
_MS_REMOUNT, _MS_BIND, _MS_REC = 32, 4096, 16384
_MS_NOATIME, _MS_NODIRATIME, _MS_RELATIME = 1024, 2048, 1 << 21
_ST_RELATIME = 4096
_CLONE_NEWUSER = 0x10000000
_PR_SET_DUMPABLE, _PR_SET_NO_NEW_PRIVS = 4, 38
_UID_BASE = 200_000  # job uids: 200000 + ROS domain (no account, owns nothing else)


def job_uid(domain: int) -> int:
    """The unprivileged uid (and gid) a job of a root grader runs as: one per job slot."""
    return _UID_BASE + domain


def _libc() -> ctypes.CDLL:
    return ctypes.CDLL(ctypes.util.find_library('c') or 'libc.so.6', use_errno=True)


def _bytes(text: str | None) -> bytes | None:
    return text.encode() if text is not None else None


def _mount(source: str | None, target: str, fstype: str | None, flags: int,
           data: str | None = None) -> None:
    libc = _libc()
    if libc.mount(_bytes(source), target.encode(), _bytes(fstype), ctypes.c_ulong(flags),
                  _bytes(data)) != 0:
        err = ctypes.get_errno()
        raise OSError(err, f'mount {target}: {os.strerror(err)}')


def _kept_flags(path: str) -> int:
    """The flags a remount of `path` must keep (a user namespace may not clear them)."""
    flag = os.statvfs(path).f_flag
    kept = flag & (_MS_NOSUID | _MS_NODEV | _MS_NOEXEC | _MS_NOATIME | _MS_NODIRATIME)
    return kept | (_MS_RELATIME if flag & _ST_RELATIME else 0)


def _remount(path: str, read_only: bool) -> None:
    flags = _MS_REMOUNT | _MS_BIND | _kept_flags(path) | (_MS_RDONLY if read_only else 0)
    _mount(None, path, None, flags)


def _mount_points() -> list[str]:
    points = []
    for line in Path('/proc/self/mountinfo').read_text().splitlines():
        field = line.split()[4]
        points.append(field.encode().decode('unicode_escape'))  # '\040' -> ' '
    return points


def _needed_paths() -> list[Path]:
    """What the job's Python and the kit read: the venv, the base Python, sys.path, the
    kit's package, AMENT_PREFIX_PATH, PATH and LD_LIBRARY_PATH entries."""
    import robot_lab

    found = [sys.prefix, sys.base_prefix, sys.exec_prefix, str(Path(robot_lab.__file__).parent),
             *sys.path]
    for var in ('AMENT_PREFIX_PATH', 'PATH', 'LD_LIBRARY_PATH', 'PYTHONPATH'):
        found += os.environ.get(var, '').split(os.pathsep)
    paths = []
    for item in found:
        if item and os.path.isabs(item) and os.path.exists(item):
            paths.append(Path(item).resolve())
    return paths


def _outermost(paths: Iterable[Path]) -> list[Path]:
    chosen: list[Path] = []
    for path in sorted(set(paths), key=lambda p: len(p.parts)):
        if not any(path.is_relative_to(c) for c in chosen):
            chosen.append(path)
    return chosen


def _hidden_tops() -> list[Path]:
    tops = []
    for entry in sorted(Path('/').iterdir()):
        if entry.name not in SYSTEM_DIRS and entry.is_dir() and not entry.is_symlink():
            tops.append(entry)
    return tops


def _bind(fd: int, target: Path, is_dir: bool) -> None:
    if is_dir:
        target.mkdir(parents=True, exist_ok=True)
    else:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.touch(exist_ok=True)
    _mount(f'/proc/self/fd/{fd}', str(target), None, _MS_BIND | _MS_REC)


def confine(job_dir: Path) -> list[str]:
    """Make this mount namespace the job's view (see the module doc); the mounts that could
    not be changed (an empty list when all went as planned)."""
    job_dir = job_dir.resolve()
    hidden = _hidden_tops()
    covered = [*hidden, *(Path(p) for p in PRIVATE_TMP)]
    keep = [p for p in _outermost(_needed_paths())
            if any(p.is_relative_to(h) for h in covered) and p != job_dir
            and not p.is_relative_to(job_dir)]
    fds = {p: os.open(p, os.O_PATH) for p in [*keep, job_dir]}
    folders = {p for p in keep if p.is_dir()}  # asked now: soon they are covered
    cwd = os.getcwd()
    problems: list[str] = []
    try:
        for point in _mount_points():
            if point == '/proc' or point.startswith('/proc/'):
                continue
            try:
                _remount(point, read_only=True)
            except OSError as err:
                if os.path.exists(point):
                    problems.append(f'{point}: {err.strerror}')
        for tmp in PRIVATE_TMP:
            if os.path.isdir(tmp):
                _mount('tmpfs', tmp, 'tmpfs', _MS_NOSUID | _MS_NODEV, 'mode=1777,size=1g')
        for top in hidden:
            _mount('tmpfs', str(top), 'tmpfs', _MS_NOSUID | _MS_NODEV, 'mode=755,size=16m')
        for path in keep:
            _bind(fds[path], path, path in folders)
            _remount(str(path), read_only=True)
        _bind(fds[job_dir], job_dir, True)
        _remount(str(job_dir), read_only=False)
        for top in hidden:
            _remount(str(top), read_only=True)
    finally:
        for fd in fds.values():
            os.close(fd)
    with contextlib.suppress(OSError):
        os.chdir(cwd)  # through the new mounts (the old folder is now read-only)
    return problems


def drop_privileges(uid: int | None) -> None:
    """As root, become `uid` (no capabilities); otherwise a nested user namespace, where
    this process holds no capability over the job's mounts. Either way no_new_privs, and
    not dumpable (the job's memory and fds stay out of its children's reach)."""
    libc = _libc()
    if uid is not None and os.geteuid() == 0:
        os.setgroups([])
        os.setresgid(uid, uid, uid)
        os.setresuid(uid, uid, uid)
    elif libc.unshare(_CLONE_NEWUSER) != 0:
        err = ctypes.get_errno()
        raise OSError(err, f'cannot enter a user namespace: {os.strerror(err)}')
    libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0)
    libc.prctl(_PR_SET_DUMPABLE, 0, 0, 0, 0)


def leftover_processes(keep: Iterable[int] = ()) -> list[tuple[int, str]]:
    """Processes in the job's PID namespace other than this one, its init and `keep`
    (pid, command line); in a namespace of its own, every one is the job's."""
    import psutil

    mine = {os.getpid(), 1, *keep}
    with contextlib.suppress(psutil.Error):
        mine.update(p.pid for p in psutil.Process().children(recursive=True))
    found = []
    for proc in psutil.process_iter(['pid', 'cmdline']):
        if proc.pid in mine:
            continue
        with contextlib.suppress(psutil.Error):
            found.append((proc.pid, ' '.join(proc.info['cmdline'] or [])[:160]))
    return found


_REFUSALS = (
    (re.compile(r"Read-only file system: '([^']+)'"),
     'a write to `{0}` was refused: a grading job may write only its own folder and /tmp'),
    (re.compile(r"No such file or directory: '(/[^']+)'"),
     '`{0}` does not exist in the sandbox: a grading job sees only its own folder, a private '
     "/tmp and the system (never other hand-ins or the instructor's files)"),
    (re.compile(r'Connection refused|Network is unreachable|\[Errno 11[13]\]|\[Errno 101\]'),
     'a network connection was refused: a grading job has only a loopback of its own'),
    (re.compile(r'Operation not permitted|\[Errno 1\]|No such process|\[Errno 3\]'),
     'an operation the sandbox does not allow was refused (a signal to a process outside the '
     'job, a privileged call)'),
    (re.compile(r'Permission denied'), 'an access the sandbox does not allow was refused'),
)


def blocked_attempts(lines: Iterable[str], job_dir: Path) -> list[str]:
    """What the sandbox refused, as the processes' output tells it (one note per kind)."""
    notes: dict[str, str] = {}
    for line in lines:
        for pattern, note in _REFUSALS:
            found = pattern.search(line)
            if found is None or note in notes:
                continue
            path = found.group(1) if found.groups() else ''
            if path and Path(path).is_relative_to(job_dir):
                continue  # the job's own files: the student's business
            notes[note] = note.format(path) + f' (`{line.strip()[:160]}`)'
    return list(notes.values())
