"""Namespaces and mounts: unshare(2), mount(2), bind mounts and read-only remounts.

The grader's sandbox (grading/package/sandbox.py, confinement.py) makes a job's own
mount, PID, network and IPC namespaces, in a user namespace when it is not root. Ubuntu
24.04 (AppArmor's restriction of unprivileged user namespaces) and Docker's default
seccomp profile refuse that: `probe` says so, and the grader then refuses to run
students' code, root or not, saying why and how to allow namespaces, unless it is given
`--no-sandbox` (or runs in Gradescope's container, which it names as the sandbox).
"""

from __future__ import annotations

import ctypes
import os
import struct
import subprocess
import sys
from typing import NamedTuple

from robot_lab.linux import procfs
from robot_lab.linux.libc import check, libc

__all__ = ['CLONE_NEWIPC', 'CLONE_NEWNET', 'CLONE_NEWNS', 'CLONE_NEWPID', 'CLONE_NEWUSER',
           'MS_BIND', 'MS_NODEV', 'MS_NOEXEC', 'MS_NOSUID', 'MS_PRIVATE', 'MS_RDONLY', 'MS_REC',
           'MS_REMOUNT', 'Restrictions', 'bind', 'bind_descriptor', 'drop_capabilities',
           'in_initial_user_namespace', 'job_namespaces', 'kept_flags', 'map_ids', 'mount',
           'probe', 'remount', 'restrictions', 'unmount', 'unshare']

CLONE_NEWNS, CLONE_NEWIPC, CLONE_NEWUSER = 0x00020000, 0x08000000, 0x10000000
CLONE_NEWPID, CLONE_NEWNET = 0x20000000, 0x40000000
MS_RDONLY, MS_NOSUID, MS_NODEV, MS_NOEXEC = 1, 2, 4, 8
MS_REMOUNT, MS_BIND, MS_REC, MS_PRIVATE = 32, 4096, 16384, 1 << 18
MS_NOATIME, MS_NODIRATIME, MS_RELATIME = 1024, 2048, 1 << 21
_ST_RELATIME = 4096
MNT_DETACH = 2
_CAPABILITY_V3 = 0x20080522  # _LINUX_CAPABILITY_VERSION_3
_PROBE_TIMEOUT = 10.0


def _bytes(text: str | None) -> bytes | None:
    return os.fsencode(text) if text is not None else None


def job_namespaces() -> int:
    """The namespaces a grading job gets: mount, PID, network, IPC, and a user namespace
    to make them in unless this process is root."""
    flags = CLONE_NEWNS | CLONE_NEWPID | CLONE_NEWNET | CLONE_NEWIPC
    return flags if os.geteuid() == 0 else flags | CLONE_NEWUSER


def unshare(flags: int) -> None:
    """Move this process into new namespaces (`CLONE_NEW*` flags); OSError if refused."""
    check(libc().unshare(flags), f'unshare({flags:#x})')


def mount(source: str | None, target: str, fstype: str | None, flags: int,
          data: str | None = None) -> None:
    """mount(2); OSError naming the target if refused."""
    check(libc().mount(_bytes(source), _bytes(target), _bytes(fstype), ctypes.c_ulong(flags),
                       _bytes(data)), f'mount {target}')


def kept_flags(path: str) -> int:
    """The flags a remount of `path` must keep (a user namespace may not clear them)."""
    flag = os.statvfs(path).f_flag
    kept = flag & (MS_NOSUID | MS_NODEV | MS_NOEXEC | MS_NOATIME | MS_NODIRATIME)
    return kept | (MS_RELATIME if flag & _ST_RELATIME else 0)


def remount(path: str, read_only: bool) -> None:
    """Remount the bind mount at `path` read-only or writable, keeping its other flags."""
    flags = MS_REMOUNT | MS_BIND | kept_flags(path) | (MS_RDONLY if read_only else 0)
    mount(None, path, None, flags)


def bind(source: str, target: str, recursive: bool = True) -> None:
    """Bind the path `source` at `target`."""
    mount(source, target, None, MS_BIND | (MS_REC if recursive else 0))


def bind_descriptor(fd: int, target: str, recursive: bool = True) -> None:
    """Bind what the descriptor `fd` (O_PATH will do) names at `target`: its path may be
    covered by another mount by now, the descriptor still reaches it (/proc/self/fd/N)."""
    bind(f'/proc/self/fd/{fd}', target, recursive)


def unmount(target: str, detach: bool = False) -> None:
    """umount2(2) (MNT_DETACH: lazily, once no one uses it); OSError if refused."""
    check(libc().umount2(_bytes(target), MNT_DETACH if detach else 0), f'umount {target}')


def in_initial_user_namespace() -> bool:
    """True in the machine's own user namespace, where every uid maps to itself; False in
    one that `unshare --user` (or `unshare(CLONE_NEWUSER)`) made."""
    try:
        with open('/proc/self/uid_map', encoding='ascii') as file:
            return file.read().split() == ['0', '0', '4294967295']
    except OSError:
        return True  # no user namespaces on this kernel: the machine's own


def map_ids(inner_uid: int, inner_gid: int, outer_uid: int, outer_gid: int) -> None:
    """Right after unshare(CLONE_NEWUSER): map one uid and one gid of the new namespace to
    the ones this process had outside (setgroups denied first, as the kernel requires of an
    unprivileged writer); OSError if refused."""
    for name, line in (('setgroups', 'deny'), ('uid_map', f'{inner_uid} {outer_uid} 1'),
                       ('gid_map', f'{inner_gid} {outer_gid} 1')):
        with open(f'/proc/self/{name}', 'w', encoding='ascii') as file:
            file.write(line)


def drop_capabilities() -> None:
    """Empty this thread's effective, permitted and inheritable capability sets (capset(2),
    version 3); a process forked later without an exec holds none either."""
    header = struct.pack('=Ii', _CAPABILITY_V3, 0)
    check(libc().capset(header, bytes(24)), 'capset')


class Restrictions(NamedTuple):
    """What this machine sets that refuses namespaces (the fix for each differs)."""

    apparmor: bool  # kernel.apparmor_restrict_unprivileged_userns=1 (Ubuntu 24.04)
    userns_clone_off: bool  # kernel.unprivileged_userns_clone=0 (Debian's older kernels)
    zero_limits: tuple[str, ...]  # kinds (mnt, net, pid, ipc, user) whose user.max_* is 0
    seccomp: bool  # this process runs under a seccomp filter (Docker's default profile)


def restrictions() -> Restrictions:
    """The settings of this kernel and process that refuse namespaces (read, not tried:
    `probe` says whether they are refused)."""
    try:
        seccomp = procfs.status().get('Seccomp') == '2'  # 2: a filter, 1: strict mode
    except OSError:
        seccomp = False
    return Restrictions(
        apparmor=procfs.sysctl('kernel.apparmor_restrict_unprivileged_userns') == '1',
        userns_clone_off=procfs.sysctl('kernel.unprivileged_userns_clone') == '0',
        zero_limits=tuple(kind for kind in ('mnt', 'net', 'pid', 'ipc', 'user')
                          if procfs.sysctl(f'user.max_{kind}_namespaces') == '0'),
        seccomp=seccomp)


def _try_in_child() -> int:
    """In a fresh process: make the job's namespaces and mount a tmpfs in them, as the
    sandbox will; 0 if the kernel allowed it, else the errno. (Ubuntu 24.04 lets an
    unprivileged unshare through but takes its capabilities: the mount is what fails.)"""
    import tempfile

    uid, gid, flags = os.getuid(), os.getgid(), job_namespaces()
    folder = tempfile.mkdtemp(prefix='robot_lab_probe_')
    try:
        unshare(flags)
        if flags & CLONE_NEWUSER:
            map_ids(0, 0, uid, gid)
        mount(None, '/', None, MS_REC | MS_PRIVATE)
        mount('tmpfs', folder, 'tmpfs', MS_NOSUID | MS_NODEV, 'size=1m')
        unmount(folder)
    except OSError as exc:
        return exc.errno or 1
    finally:
        os.rmdir(folder)
    return 0


def probe() -> str | None:
    """Whether a process here may make a grading job's namespaces and mount in them
    (asked in a child process: unshare cannot be undone)."""
    try:
        done = subprocess.run([sys.executable, '-m', 'robot_lab.linux.namespaces'],
                              capture_output=True, timeout=_PROBE_TIMEOUT, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f'cannot run the probe: {exc}'
    if done.returncode == 0:
        return None
    return (f"unshare refused: {os.strerror(done.returncode)} (a container's seccomp "
            'profile, or user namespaces restricted, as on Ubuntu 24.04)')


if __name__ == '__main__':
    sys.exit(_try_in_child())
