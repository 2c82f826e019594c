"""Temporary Unix users for the isolation and hub tests (root only).

Each user gets a home under a world-traversable temporary folder and runs commands with
`setpriv` (parent-death signal kept, so nothing outlives pytest). The venv's interpreter
may live where other users cannot go (e.g. /root/.pyenv): then every command runs in a
private mount namespace where a tmpfs covers the closed folder and only the interpreter's
tree is bound back in. With `netns`, commands run in a network namespace holding only
loopback (SUBNET discovery then cannot reach a LAN).
"""

from __future__ import annotations

import contextlib
import os
import pwd
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

BIN = Path(sys.executable).parent


def can_create_users() -> str | None:
    """None when this process can create users and switch to them; else why not."""
    if os.geteuid() != 0:
        return 'needs root to create temporary Unix users (useradd, setpriv)'
    for tool in ('useradd', 'userdel', 'setpriv', 'unshare', 'nsenter', 'ip'):
        if shutil.which(tool) is None:
            return f'{tool} is not installed'
    return None


def _closed_ancestor() -> tuple[Path, Path] | None:
    """(folder others cannot enter, its child on the interpreter's path), if any."""
    real = Path(os.path.realpath(sys.executable))
    for parent in reversed(real.parents):
        if parent != Path('/') and not parent.stat().st_mode & 0o001:
            return parent, parent / real.relative_to(parent).parts[0]
    return None


@dataclass
class User:
    name: str
    uid: int
    gid: int
    home: Path


class UnixUsers:
    """Creates users on demand; `command()` wraps an argv to run as one of them."""

    def __init__(self, root: Path, netns: bool = False) -> None:
        self.root = root
        self.users: dict[str, User] = {}
        self._prefix = f'rl{os.getpid() % 100000}'
        self._closed = _closed_ancestor()
        self._hold = root / 'hold'
        self._hold.mkdir()
        self._netns: subprocess.Popen[bytes] | None = None
        if netns:
            # Lives until its stdin closes; every wrapped command joins its network.
            self._netns = subprocess.Popen(
                ['unshare', '-n', 'sh', '-c',
                 'ip link set lo up && ip link set lo multicast on && echo up && exec cat'],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
            assert self._netns.stdout is not None
            assert self._netns.stdout.readline().strip() == b'up'

    def add(self, short: str) -> User:
        name = f'{self._prefix}{short}'
        home = self.root / name
        subprocess.run(['useradd', '--create-home', '--home-dir', str(home),
                        '--shell', '/bin/sh', '--user-group', name], check=True)
        entry = pwd.getpwnam(name)
        user = User(name, entry.pw_uid, entry.pw_gid, home)
        self.users[short] = user
        return user

    def env(self, user: User, extra: Mapping[str, str] | None = None) -> dict[str, str]:
        """A clean login-like environment (no ROS_DOMAIN_ID) for `user`."""
        env = {'HOME': str(user.home), 'USER': user.name, 'LOGNAME': user.name,
               'PATH': f'{BIN}:/usr/local/bin:/usr/bin:/bin', 'LANG': 'C.UTF-8',
               'SHELL': '/bin/sh'}
        env.update(extra or {})
        return env

    def command(self, user: User | None, argv: Sequence[str]) -> list[str]:
        """`argv` run as `user` (same pid: every wrapper execs the next); `None`: as root,
        in the same file system view (a JupyterHub that starts the users' servers)."""
        steps = []
        if self._closed is not None:
            closed, keep = self._closed
            steps += [f'mount --bind {keep} {self._hold}',
                      f'mount -t tmpfs -o mode=0755 tmpfs {closed}',
                      f'mkdir -p {keep}', f'mount --move {self._hold} {keep}']
        if user is None:
            steps.append('exec "$@"')
        else:
            steps.append(f'exec setpriv --reuid={user.uid} --regid={user.gid} --init-groups '
                         '--pdeathsig=KILL -- "$@"')
        wrapped = ['unshare', '--mount', '--propagation', 'private', '--',
                   'sh', '-ec', ' && '.join(steps), 'sh', *argv]
        if self._netns is not None:
            wrapped = ['nsenter', f'--net=/proc/{self._netns.pid}/ns/net', '--', *wrapped]
        return wrapped

    def leftovers(self) -> list[int]:
        """Pids still running as one of these users."""
        uids = {u.uid for u in self.users.values()}
        pids = []
        for entry in Path('/proc').iterdir():
            if entry.name.isdigit():
                with contextlib.suppress(OSError):
                    if entry.stat().st_uid in uids:
                        pids.append(int(entry.name))
        return pids

    def close(self) -> list[int]:
        """Kill what the users left running (returned), remove them and their homes."""
        left = self.leftovers()
        for pid in left:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, 9)
        for user in self.users.values():
            subprocess.run(['userdel', '--remove', user.name], check=False,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if self._netns is not None:
            assert self._netns.stdin is not None
            self._netns.stdin.close()
            self._netns.wait(10)
        shutil.rmtree(self.root, ignore_errors=True)
        return left


@contextlib.contextmanager
def unix_users(netns: bool = False) -> Iterator[UnixUsers]:
    """A UnixUsers in a fresh world-traversable folder; everything removed afterwards."""
    root = Path(tempfile.mkdtemp(prefix='robot_lab_users_', dir='/tmp'))
    root.chmod(0o755)
    users = UnixUsers(root, netns=netns)
    try:
        yield users
    finally:
        users.close()
