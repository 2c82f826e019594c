"""Which ROS_DOMAIN_ID a process uses: the user's own, unless someone set one.

Two students on one host who both leave ROS_DOMAIN_ID unset would share domain 0 and see
(and change) each other's nodes as soon as discovery reaches across users (UDP-only
transports do). So when ROS_DOMAIN_ID is not set, every Unix user gets a domain of their
own from a host-wide registry: the same in all their kernels, terminals, launches, daemons
and `ros2` commands, stable across logins, and never shared (an allocation under a lock,
not a hash that can collide). `ROS_DOMAIN_ID` set by the user or the hub always wins.

Which domains: Fast DDS puts domain d on UDP ports 7400 + 250 d + ..., so 0-101 stay
below Linux's ephemeral port range (32768-60999) and 215-232 above it. Users get 1-101
(101 users; 0 stays what a process started without the kit uses). Parallel jobs (test
modules, grading runs) lease domains for as long as they run: 215-232 first, then free
user domains from the top. Past 101 users the answer is one container per user.

The registry is a small JSON file (ROBOT_LAB_DOMAIN_REGISTRY, else a hub's
/srv/robot_lab/domains.json if there is one, else /var/tmp/robot_lab/domains.json),
changed only under an exclusive flock and written in place (a sticky shared directory lets
no user replace another's file). `robot-lab domain list` prints it; `robot-lab domain
release USER` frees a user's entry.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import fcntl
import functools
import json
import os
import pwd
import sys
import time
from collections.abc import Iterator, Mapping, MutableMapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Literal

from robot_lab.errors import RobotLabError
from robot_lab.linux.procfs import start_time

__all__ = [
    'DEFAULT_REGISTRY',
    'FROM_REGISTRY_VARIABLE',
    'HUB_REGISTRY',
    'JOB_DOMAINS',
    'JOB_POOL_VARIABLE',
    'POOL_VARIABLE',
    'REGISTRY_VARIABLE',
    'USER_DOMAINS',
    'DomainChoice',
    'DomainRegistry',
    'domain_for',
    'domain_ports',
    'fill_domain',
    'find_user',
    'job_pool',
    'lease_domains',
    'listing',
    'process_domain',
    'release_user',
    'resolve',
    'user_domain',
]

REGISTRY_VARIABLE = 'ROBOT_LAB_DOMAIN_REGISTRY'
# Set beside ROS_DOMAIN_ID when the kit filled it in from the registry, so a child (a
# terminal's `ros2 doctor` from a kernel) still says why it has that domain.
FROM_REGISTRY_VARIABLE = 'ROBOT_LAB_DOMAIN_FROM_REGISTRY'
# `first-last` domains handed to users (an admin may narrow it; tests use their own).
POOL_VARIABLE = 'ROBOT_LAB_USER_DOMAINS'
# `first-last` domains the grader's (and tests') parallel jobs lease first.
JOB_POOL_VARIABLE = 'ROBOT_LAB_JOB_DOMAINS'
# Fast DDS's well-known ports (RTPS 2.x 9.6.1.1): PB + DG * domain and up.
_PORT_BASE, _DOMAIN_GAIN = 7400, 250


def domain_ports(domain: int) -> range:
    """The port numbers of a domain's participants (UDP, and Fast DDS's shared-memory
    ports of the domain: those below 7400 are tried by every participant of the host)."""
    return range(_PORT_BASE + _DOMAIN_GAIN * domain, _PORT_BASE + _DOMAIN_GAIN * (domain + 1))


DEFAULT_REGISTRY = Path('/var/tmp/robot_lab/domains.json')
# Where a hub keeps its users' registry (deploy/tljh: outside the per-user /tmp, /var/tmp).
HUB_REGISTRY = Path('/srv/robot_lab/domains.json')
USER_DOMAINS = range(1, 102)
JOB_DOMAINS = range(215, 233)
_VALID = (*range(0, 102), *range(215, 233))

_FIX_FULL = ('give each student a container of their own (Zero to JupyterHub on Kubernetes, '
             'docs/deploy.md), set ROS_DOMAIN_ID per user in the hub, or free the entries '
             'of users who left: robot-lab domain release USER')


def registry_path(env: Mapping[str, str] | None = None) -> Path:
    """ROBOT_LAB_DOMAIN_REGISTRY (what a hub sets for its users' servers), else a hub's
    registry on this host (an admin's shell, sudo: the hub's variable is not there), else
    the default."""
    source = os.environ if env is None else env
    named = source.get(REGISTRY_VARIABLE, '').strip()
    if named:
        return Path(named)
    return HUB_REGISTRY if HUB_REGISTRY.is_file() else DEFAULT_REGISTRY


def user_pool(env: Mapping[str, str] | None = None) -> range:
    """The user domains: USER_DOMAINS, or `first-last` from ROBOT_LAB_USER_DOMAINS."""
    return _pool(POOL_VARIABLE, USER_DOMAINS, env, 'e.g. 1-101')


def job_pool(env: Mapping[str, str] | None = None) -> range:
    """The domains jobs lease first: JOB_DOMAINS, or `first-last` from ROBOT_LAB_JOB_DOMAINS
    (a host whose network already uses 215-232; two registries on one host, each its own
    part: DDS domains are the host's, whatever file books them)."""
    return _pool(JOB_POOL_VARIABLE, JOB_DOMAINS, env, 'e.g. 215-232')


def _job_order(env: Mapping[str, str] | None) -> list[int]:
    """Where a job's lease looks: the job domains, then the user domains from the top."""
    return [*job_pool(env), *reversed(user_pool(env))]


def _pool(variable: str, default: range, env: Mapping[str, str] | None, example: str) -> range:
    source = os.environ if env is None else env
    raw = source.get(variable, '').strip()
    if not raw:
        return default
    first, _, last = raw.partition('-')
    try:
        pool = range(int(first), int(last or first) + 1)
    except ValueError:
        pool = range(0)
    if not pool or not all(d in _VALID for d in pool):
        raise RobotLabError(f'{variable}={raw!r} is not a range of valid domains',
                            fix=f'use FIRST-LAST within 0-101 or 215-232, {example}')
    return pool


def _user_name(uid: int) -> str:
    try:
        return pwd.getpwuid(uid).pw_name
    except KeyError:
        return f'uid {uid}'


class DomainRegistry:
    """The host's table of users' domains and jobs' leases, in one locked JSON file."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def _open(self) -> IO[str]:
        directory = self.path.parent
        try:
            if not directory.is_dir():
                directory.mkdir(parents=True, exist_ok=True)
                with contextlib.suppress(OSError):  # shared by every user, like /tmp
                    directory.chmod(0o1777)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise RobotLabError(
                f'cannot open the ROS domain registry {self.path}: {exc.strerror}',
                fix=f'set ROS_DOMAIN_ID yourself, or point {REGISTRY_VARIABLE} at a file '
                'every user can write') from None
        with contextlib.suppress(OSError):
            if os.fstat(fd).st_uid == os.getuid():
                os.fchmod(fd, 0o666)  # every user adds their own entry
        return os.fdopen(fd, 'r+', encoding='utf-8')

    @contextlib.contextmanager
    def locked(self) -> Iterator[dict[str, Any]]:
        """The table, for reading and changing; written back in place on exit."""
        with self._open() as file:
            fcntl.flock(file, fcntl.LOCK_EX)
            text = file.read()
            try:
                data = json.loads(text) if text.strip() else {}
                if not isinstance(data, dict):
                    raise ValueError('not an object')
            except ValueError:
                raise RobotLabError(
                    f'the ROS domain registry {self.path} is damaged',
                    fix='fix or remove it (users then get new domains at their next start)',
                ) from None
            data.setdefault('users', {})
            data.setdefault('leases', {})
            before = json.dumps(data, sort_keys=True)
            yield data
            after = json.dumps(data, indent=1, sort_keys=True)
            if json.dumps(data, sort_keys=True) != before:
                file.seek(0)
                file.write(after + '\n')
                file.truncate()
                file.flush()
                os.fsync(file.fileno())

    def read(self) -> dict[str, Any]:
        with self.locked() as data:
            self._live_leases(data)
            copy: dict[str, Any] = json.loads(json.dumps(data))
            return copy

    @staticmethod
    def _live_leases(data: dict[str, Any]) -> dict[int, dict[str, Any]]:
        """Leases whose holder still runs; the others are dropped from `data`."""
        live = {}
        for key, lease in list(data['leases'].items()):
            if start_time(int(lease.get('pid', 0))) == lease.get('start'):
                live[int(key)] = lease
            else:
                del data['leases'][key]
        return live

    def user_domain(self, uid: int, pool: range) -> int:
        """The domain of user `uid`, allocated (lowest free in `pool`) on first use."""
        with self.locked() as data:
            entry = data['users'].get(str(uid))
            if entry is not None:
                return int(entry['domain'])
            taken = {int(e['domain']) for e in data['users'].values()}
            taken |= set(self._live_leases(data))
            free = [d for d in pool if d not in taken]
            if not free:
                raise RobotLabError(
                    f'no ROS domain left for {_user_name(uid)}: all {len(pool)} user domains '
                    f'({pool.start}-{pool.stop - 1}) in {self.path} are taken', fix=_FIX_FULL)
            data['users'][str(uid)] = {'domain': free[0], 'name': _user_name(uid),
                                       'since': time.strftime('%Y-%m-%dT%H:%M:%S%z')}
            return free[0]

    def lease(self, count: int, pool: Sequence[int], purpose: str) -> list[int]:
        """`count` domains held by this process until `release` (or its death)."""
        pid = os.getpid()
        with self.locked() as data:
            taken = {int(e['domain']) for e in data['users'].values()}
            taken |= set(self._live_leases(data))
            free = [d for d in pool if d not in taken]
            if len(free) < count:
                raise RobotLabError(
                    f'{purpose or "a job"} needs {count} ROS domains, {len(free)} are free '
                    f'in {self.path}', fix='wait for other jobs to end, or run fewer at once')
            chosen = free[:count]
            for domain in chosen:
                data['leases'][str(domain)] = {'pid': pid, 'start': start_time(pid),
                                               'uid': os.getuid(), 'purpose': purpose}
            return chosen

    def release(self, domains: Sequence[int]) -> None:
        with self.locked() as data:
            for domain in domains:
                lease = data['leases'].get(str(domain))
                if lease is not None and lease.get('pid') == os.getpid():
                    del data['leases'][str(domain)]

    def release_user(self, uid: int) -> int | None:
        with self.locked() as data:
            entry = data['users'].pop(str(uid), None)
            return None if entry is None else int(entry['domain'])


@functools.lru_cache(maxsize=8)
def _cached_user_domain(uid: int, path: Path, pool: range) -> int:
    return DomainRegistry(path).user_domain(uid, pool)


def user_domain(env: Mapping[str, str] | None = None, uid: int | None = None) -> int:
    """This user's domain from the registry of `env` (allocated on first use)."""
    return _cached_user_domain(os.getuid() if uid is None else uid, registry_path(env),
                               user_pool(env))


@dataclass(frozen=True)
class DomainChoice:
    """A domain and why: `variable` (ROS_DOMAIN_ID was set) or `registry` (the user's)."""

    domain: int
    source: Literal['variable', 'registry']
    registry: Path | None = None

    def __str__(self) -> str:
        if self.source == 'variable':
            return f'{self.domain} (ROS_DOMAIN_ID set in the environment)'
        return (f"{self.domain} (user {_user_name(os.getuid())}'s own domain, "
                f'from the registry {self.registry})')


def resolve(env: Mapping[str, str] | None = None) -> DomainChoice:
    """The domain for a process with environment `env` (default: os.environ), and why."""
    source = os.environ if env is None else env
    raw = source.get('ROS_DOMAIN_ID', '').strip()
    if raw and raw == source.get(FROM_REGISTRY_VARIABLE):
        return DomainChoice(int(raw), 'registry', registry_path(source))
    if raw:
        try:
            return DomainChoice(int(raw), 'variable')
        except ValueError:
            raise RobotLabError(f'ROS_DOMAIN_ID={raw!r} is not a number',
                                fix='set it to an integer 0..101, or unset it') from None
    return DomainChoice(user_domain(source), 'registry', registry_path(source))


def fill_domain(env: MutableMapping[str, str]) -> None:
    """Set ROS_DOMAIN_ID in `env` to the user's own domain unless it is set already."""
    if not env.get('ROS_DOMAIN_ID', '').strip():
        domain = str(user_domain(env))
        env['ROS_DOMAIN_ID'] = env[FROM_REGISTRY_VARIABLE] = domain


def domain_for(env: Mapping[str, str] | None = None) -> int:
    """Just the number of `resolve(env)`."""
    return resolve(env).domain


@contextlib.contextmanager
def lease_domains(count: int, purpose: str = '', pool: Sequence[int] | None = None,
                  env: Mapping[str, str] | None = None) -> Iterator[list[int]]:
    """`count` domains reserved host-wide while the block runs (parallel jobs: grading,
    test modules), so no user and no other job is in them. A holder killed with -9 frees
    its leases too (the next allocation sees its process gone)."""
    if pool is None:
        pool = _job_order(env)
    registry = DomainRegistry(registry_path(env))
    domains = registry.lease(count, pool, purpose)
    try:
        yield domains
    finally:
        registry.release(domains)


_process_lease: list[int] = []


def process_domain(purpose: str, env: Mapping[str, str] | None = None) -> int:
    """One domain leased for as long as this process lives (an autograded notebook's
    kernel): no user's, no other job's. Asked again, the same one; freed at exit, or by
    the next allocation once the process is gone (kill -9 included)."""
    if not _process_lease:
        registry = DomainRegistry(registry_path(env))
        _process_lease.extend(registry.lease(1, _job_order(env), purpose))
        atexit.register(registry.release, list(_process_lease))
    return _process_lease[0]


def find_user(name: str, data: Mapping[str, Any]) -> tuple[int, str]:
    """(uid, Unix name) of the registry's entry for `name`: a Unix name, a hub name whose
    Unix user is `jupyter-<name>` (The Littlest JupyterHub), a uid, or a name the
    registry remembers (a user already deleted)."""
    users = data.get('users', {})
    for candidate in (name, f'jupyter-{name}'):
        with contextlib.suppress(KeyError):
            uid = pwd.getpwnam(candidate).pw_uid
            if str(uid) in users:
                return uid, candidate
    if name.isdigit() and name in users:
        return int(name), str(users[name].get('name', name))
    for uid, entry in users.items():
        if entry.get('name') in (name, f'jupyter-{name}'):
            return int(uid), str(entry['name'])
    raise RobotLabError(f'{name!r} has no domain in the registry', fix='`robot-lab domain '
                        'list` shows who has one (a hub user NAME is Unix user jupyter-NAME)')


def release_user(name: str, env: Mapping[str, str] | None = None) -> tuple[str, int]:
    """Free the domain of user `name` (see `find_user`); (their Unix name, the domain)."""
    registry = DomainRegistry(registry_path(env))
    uid, unix = find_user(name, registry.read())
    freed = registry.release_user(uid)
    if freed is None:  # released by someone else just now
        raise RobotLabError(f'{name!r} has no domain in the registry',
                            fix='`robot-lab domain list` shows who has one')
    return unix, freed


def listing(env: Mapping[str, str] | None = None) -> list[str]:
    """The registry, as `robot-lab domain list` prints it."""
    registry = DomainRegistry(registry_path(env))
    data = registry.read()
    lines = [f'{registry.path}:']
    for uid, entry in sorted(data['users'].items(), key=lambda kv: kv[1]['domain']):
        lines.append(f"  domain {entry['domain']:>3}  {entry.get('name', '?')} (uid {uid})")
    for domain, lease in sorted(data['leases'].items(), key=lambda kv: int(kv[0])):
        lines.append(f"  domain {int(domain):>3}  leased by pid {lease['pid']} "
                     f"({lease.get('purpose') or 'a job'})")
    return lines


def _main(argv: list[str] | None = None) -> int:
    """`python -m robot_lab.domain [--release USER]`: `robot-lab domain` by its old name."""
    parser = argparse.ArgumentParser(prog='python -m robot_lab.domain',
                                     description='The host ROS domain registry '
                                     '(robot-lab domain list|release USER)')
    parser.add_argument('--release', metavar='USER', help="free USER's domain")
    args = parser.parse_args(argv)
    try:
        if args.release:
            unix, freed = release_user(args.release)
            print(f'{unix}: domain {freed} freed')
        else:
            print('\n'.join(listing()))
    except RobotLabError as err:
        print(err, file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(_main())
