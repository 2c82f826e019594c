"""What a grading job may see and who it is: a read-only machine, its own folder, no one's
privileges.

Run by `sandbox.enter()` first thing in the job, inside its new mount, PID, network and
IPC namespaces (and a user namespace when the grader is not root), before any student
code: every mount becomes read-only; `/tmp`, `/var/tmp` and `/dev/shm` are fresh private
tmpfs; every top-level folder that is not the system's (`/home`, `/root`, `/work`, `/run`,
`/mnt`, …) is covered by an empty read-only tmpfs, with only what the job needs bound back
read-only (the venv, the Python it runs on, the kit's package); the job folder is bound back
writable at its own path. So the job cannot read or write other students' hand-ins, the
instructor's home or the output folder.

It still looks like a machine to honest code (issue 51: a job's uid had no passwd entry, and
a correct package whose nodes called `getpass.getuser()` lost 7 of 13 points): a synthetic
`/etc/passwd` and `/etc/group` name the job's uid and gid `student`, with the job's writable
home, and `/etc/hosts` resolves localhost and this host's name to loopback (the grader sets
HOME, USER, LOGNAME and a UTF-8 locale; /dev and a /proc of the job's own stay).

Then the job gives up its privileges and becomes uid 200000+domain with no capabilities: as
root by setresuid (the grader chowned the job folder to it); otherwise in one more user
namespace that maps that uid to the grader's, where it holds no capability over its mounts.
`no_new_privs` keeps set-uid programs from giving any back.
"""

from __future__ import annotations

import contextlib
import os
import re
import socket
import sys
from collections.abc import Iterable
from pathlib import Path

from robot_lab.linux import namespaces, prctl, procfs
from robot_lab.linux.namespaces import (
    MS_NODEV,
    MS_NOEXEC,
    MS_NOSUID,
    bind,
    in_initial_user_namespace,
    mount,
    remount,
)

__all__ = ['JOB_USER', 'SYSTEM_DIRS', 'blocked_attempts', 'confine', 'drop_privileges',
           'hidden_tops', 'job_uid', 'leftover_processes', 'machine_files']

# Top-level folders a job sees (read-only); every other one is hidden.
SYSTEM_DIRS = frozenset({'bin', 'sbin', 'lib', 'lib32', 'lib64', 'libx32', 'usr', 'etc',
                         'opt', 'var', 'proc', 'sys', 'dev', 'tmp'})
PRIVATE_TMP = ('/tmp', '/var/tmp', '/dev/shm')
_UID_BASE = 200_000  # job uids: 200000 + ROS domain (no host account, owns nothing else)
JOB_USER = 'student'  # the job's name in its own /etc/passwd and /etc/group


def job_uid(domain: int) -> int:
    """The unprivileged uid (and gid) a job of a root grader runs as: one per job slot."""
    return _UID_BASE + domain


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


def hidden_tops() -> list[Path]:
    """The top-level folders a job does not see (each covered by an empty tmpfs)."""
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
    namespaces.bind_descriptor(fd, str(target))


def _entries(text: str, name: str, number: int) -> list[str]:
    """The lines of a passwd or group file minus any for `name` or id `number`."""
    kept = []
    for line in text.splitlines():
        fields = line.split(':')
        if len(fields) > 2 and (fields[0] == name or fields[2] == str(number)):
            continue
        kept.append(line)
    return kept


def machine_files(uid: int, home: Path, passwd: str, group: str, hostname: str) -> dict[str, str]:
    """What a job sees as /etc/passwd, /etc/group and /etc/hosts: the machine's accounts plus
    the job's own (`JOB_USER`, `uid` as uid and gid, `home`), and loopback names."""
    user = f'{JOB_USER}:x:{uid}:{uid}:robot_lab grading job:{home}:/bin/sh'
    hosts = ['127.0.0.1\tlocalhost', '::1\tlocalhost ip6-localhost ip6-loopback']
    if hostname and hostname != 'localhost':
        hosts.append(f'127.0.1.1\t{hostname}')
    return {'/etc/passwd': '\n'.join([*_entries(passwd, JOB_USER, uid), user]) + '\n',
            '/etc/group': '\n'.join([*_entries(group, JOB_USER, uid),
                                      f'{JOB_USER}:x:{uid}:']) + '\n',
            '/etc/hosts': '\n'.join(hosts) + '\n'}


def _read(path: str) -> str:
    try:
        return Path(path).read_text(errors='replace')
    except OSError:
        return ''


def _mount_machine_files(uid: int, home: Path) -> list[str]:
    """Bind the job's /etc/passwd, /etc/group and /etc/hosts over the machine's, read-only.

    They are written in a tmpfs mounted in the private /tmp, bound into place and then
    detached: only the read-only binds still reach it, so no one can change them.
    """
    files = machine_files(uid, home, _read('/etc/passwd'), _read('/etc/group'),
                          socket.gethostname())
    staging = Path('/tmp/.robot_lab_machine')
    try:
        staging.mkdir(mode=0o700)
        mount('tmpfs', str(staging), 'tmpfs', MS_NOSUID | MS_NODEV | MS_NOEXEC,
              'mode=755,size=1m')
    except OSError as err:  # the machine's own files stay: the job still runs
        with contextlib.suppress(OSError):
            staging.rmdir()
        return [f'{", ".join(files)}: {err.strerror}']
    problems = []
    try:
        for target, text in files.items():
            source = staging / Path(target).name
            source.write_text(text)
            source.chmod(0o644)
            try:
                bind(str(source), target, recursive=False)
                remount(target, read_only=True)
            except OSError as err:
                problems.append(f'{target}: {err.strerror}')
    finally:
        with contextlib.suppress(OSError):
            namespaces.unmount(str(staging), detach=True)
            staging.rmdir()
    return problems


def confine(job_dir: Path, uid: int | None = None, home: Path | None = None) -> list[str]:
    """Make this mount namespace the job's view (see the module doc), with `uid` named in
    its /etc/passwd (home: `home`, default job_dir/home); the mounts that could not be
    changed (an empty list when all went as planned)."""
    job_dir = job_dir.resolve()
    hidden = hidden_tops()
    covered = [*hidden, *(Path(p) for p in PRIVATE_TMP)]
    keep = [p for p in _outermost(_needed_paths())
            if any(p.is_relative_to(h) for h in covered) and p != job_dir
            and not p.is_relative_to(job_dir)]
    fds = {p: os.open(p, os.O_PATH) for p in [*keep, job_dir]}
    folders = {p for p in keep if p.is_dir()}  # asked now: soon they are covered
    cwd = os.getcwd()
    problems: list[str] = []
    try:
        for point in procfs.mount_points():
            if procfs.is_proc(point):
                continue
            try:
                remount(point, read_only=True)
            except OSError as err:
                if os.path.exists(point):
                    problems.append(f'{point}: {err.strerror}')
        for tmp in PRIVATE_TMP:
            if os.path.isdir(tmp):
                mount('tmpfs', tmp, 'tmpfs', MS_NOSUID | MS_NODEV, 'mode=1777,size=1g')
        for top in hidden:
            mount('tmpfs', str(top), 'tmpfs', MS_NOSUID | MS_NODEV, 'mode=755,size=16m')
        for path in keep:
            _bind(fds[path], path, path in folders)
            remount(str(path), read_only=True)
        _bind(fds[job_dir], job_dir, True)
        remount(str(job_dir), read_only=False)
        if uid is not None:
            problems += _mount_machine_files(uid, home or job_dir / 'home')
        for top in hidden:
            remount(str(top), read_only=True)
    finally:
        for fd in fds.values():
            os.close(fd)
    with contextlib.suppress(OSError):
        os.chdir(cwd)  # through the new mounts (the old folder is now read-only)
    return problems


def drop_privileges(uid: int | None) -> None:
    """Become `uid` with no capabilities: as the machine's root by setresuid; inside a
    non-root grader's user namespace by one more user namespace that maps `uid` to the
    grader's (this process then holds no capability over the job's mounts). Either way
    no_new_privs, and not dumpable (the job's memory and fds stay out of its children's
    reach)."""
    if in_initial_user_namespace():
        if uid is not None and os.geteuid() == 0:
            os.setgroups([])
            os.setresgid(uid, uid, uid)
            os.setresuid(uid, uid, uid)
    else:
        outer_uid, outer_gid = os.geteuid(), os.getegid()
        namespaces.unshare(namespaces.CLONE_NEWUSER)
        if uid is not None:  # one line, our own id: what a user namespace may map itself
            namespaces.map_ids(uid, uid, outer_uid, outer_gid)
    namespaces.drop_capabilities()
    prctl.set_no_new_privs()
    prctl.set_dumpable(False)


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
