"""Temporary Unix users for the isolation and hub tests (root only).

Each user gets a home under a world-traversable temporary folder and runs commands with
`setpriv` (parent-death signal kept, so nothing outlives pytest). The checkout or the
venv's interpreter may live where other users cannot go (a 0700 `mktemp -d`, /root/.pyenv):
then every command runs in a private mount namespace where a tmpfs covers each closed
folder and only the tree that is needed is bound back in. With `netns`, commands run in
a network namespace holding only loopback (SUBNET discovery then cannot reach a LAN).
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
    unreadable = _unreadable()
    if unreadable is not None:
        return (f'{unreadable} is not readable by other users (a clone made under umask '
                f'077?): run `chmod -R o+rX {REPO}` to let the test users run the kit')
    return None


REPO = Path(__file__).resolve().parent.parent


def _unreadable() -> Path | None:
    """A file of the checkout other users cannot read (a clone made under umask 077)."""
    for path in (REPO / 'robot_lab' / '__init__.py', BIN / 'robot-lab'):
        if path.exists() and not os.stat(path).st_mode & 0o004:
            return path
    return None


def _closed_ancestors() -> list[tuple[Path, list[Path]]]:
    """(folder others cannot enter, its children on paths they must reach), outermost first.

    They must reach the checkout (its venv and the editable robot_lab) and the interpreter
    the venv links to (e.g. under /root/.pyenv), wherever those live.
    """
    found: dict[Path, set[Path]] = {}
    for target in (REPO, Path(os.path.realpath(sys.executable))):
        for parent in target.parents:
            if parent != Path('/') and not parent.stat().st_mode & 0o001:
                found.setdefault(parent, set()).add(
                    parent / target.relative_to(parent).parts[0])
    return [(closed, sorted(found[closed]))
            for closed in sorted(found, key=lambda p: len(p.parts))]


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
        self._closed = _closed_ancestors()
        self._hold = root / 'hold'
        for i in range(max((len(keeps) for _, keeps in self._closed), default=0)):
            (self._hold / str(i)).mkdir(parents=True)
        self._netns: subprocess.Popen[bytes] | None = None
        if netns:
            # Lives until its stdin closes; every wrapped command joins its network.
            self._netns = subprocess.Popen(
                ['unshare', '-n', 'sh', '-c',
                 'ip link set lo up && ip link set lo multicast on && echo up && exec cat'],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
            assert self._netns.stdout is not None
            assert self._netns.stdout.readline().strip() == b'up'

    def add(self, short: str, template: str = '{}') -> User:
        """A new user `<prefix><short>`, or `template` with that in place of `{}`."""
        name = template.format(f'{self._prefix}{short}')
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
        for closed, keeps in self._closed:  # cover it, then put back only what is needed
            holds = [self._hold / str(i) for i in range(len(keeps))]
            pairs = list(zip(keeps, holds, strict=True))
            steps += [f'mount --bind {keep} {hold}' for keep, hold in pairs]
            steps.append(f'mount -t tmpfs -o mode=0755 tmpfs {closed}')
            steps += [f'mkdir -p {keep} && mount --move {hold} {keep}'
                      for keep, hold in pairs]
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
