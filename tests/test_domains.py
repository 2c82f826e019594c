"""Students kept apart by design: every Unix user's own ROS domain (robot_lab/domain.py).

The registry tests use a registry of their own and domains 93-101. The isolation test
creates real Unix users (root only) who launch the reference system without setting
ROS_DOMAIN_ID and list nodes with and without the daemon, under the default transports
(LOCALHOST and SUBNET discovery) and UDP only (SUBNET): all of it in a network namespace
holding only loopback, so SUBNET's multicast cannot reach a LAN.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, Proc
from unixusers import UnixUsers, can_create_users, unix_users

from robot_lab.domain import (
    DomainRegistry,
    domain_for,
    lease_domains,
    resolve,
)
from robot_lab.env import apply_ros_defaults
from robot_lab.errors import RobotLabError

POOL = range(93, 102)
NODES = ['/controller', '/robot', '/sensor']


def _registry_env(path: Path) -> dict[str, str]:
    return {'ROBOT_LAB_DOMAIN_REGISTRY': str(path), 'ROBOT_LAB_USER_DOMAINS': '93-101'}


def _allocate(path: str, uid: int, out: multiprocessing.Queue[int]) -> None:
    out.put(DomainRegistry(Path(path)).user_domain(uid, POOL))


def test_users_get_distinct_domains_that_stay(tmp_path: Path) -> None:
    path = tmp_path / 'domains.json'
    # Eight processes ask at once for eight users: the lock hands out eight domains.
    ctx = multiprocessing.get_context('fork')
    out: multiprocessing.Queue[int] = ctx.Queue()
    workers = [ctx.Process(target=_allocate, args=(str(path), 70000 + i, out))
               for i in range(8)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(30)
    got = sorted(out.get(timeout=5) for _ in workers)
    assert got == list(range(93, 101))
    # Stable: a later login (a new process, a new registry object) gets the same one.
    again = DomainRegistry(path)
    assert [again.user_domain(70000 + i, POOL) for i in range(8)] == [
        DomainRegistry(path).read()['users'][str(70000 + i)]['domain'] for i in range(8)]
    assert again.user_domain(70099, POOL) == 101
    with pytest.raises(RobotLabError) as err:
        again.user_domain(70100, POOL)
    assert 'all 9 user domains (93-101)' in err.value.message
    assert 'container' in (err.value.fix or '')
    assert oct(path.stat().st_mode & 0o777) == '0o666'  # every user adds their own entry


def test_the_variable_wins_and_unset_means_the_registry(tmp_path: Path) -> None:
    env = _registry_env(tmp_path / 'domains.json')
    assert resolve({**env, 'ROS_DOMAIN_ID': '7'}).source == 'variable'
    assert domain_for({**env, 'ROS_DOMAIN_ID': '7'}) == 7
    choice = resolve(env)
    assert (choice.domain, choice.source) == (93, 'registry')
    assert 'from the registry' in str(choice)
    child = apply_ros_defaults(dict(env))  # what every process the kit starts gets
    assert child['ROS_DOMAIN_ID'] == '93'
    assert resolve(child).source == 'registry'  # a child still knows why (ros2 doctor)
    assert resolve({**child, 'ROS_DOMAIN_ID': '94'}).source == 'variable'
    assert apply_ros_defaults({**env, 'ROS_DOMAIN_ID': '12'})['ROS_DOMAIN_ID'] == '12'
    doctor = subprocess.run([str(BIN / 'robot-lab'), 'doctor'], capture_output=True, text=True,
                            env={k: v for k, v in {**os.environ, **env}.items()
                                 if k != 'ROS_DOMAIN_ID'}, timeout=60, check=False)
    assert '[ok] ROS_DOMAIN_ID: 93 (user ' in doctor.stdout
    assert str(tmp_path / 'domains.json') in doctor.stdout


def test_leases_keep_users_and_jobs_apart(tmp_path: Path) -> None:
    env = _registry_env(tmp_path / 'domains.json')
    registry = DomainRegistry(tmp_path / 'domains.json')
    with lease_domains(3, 'pytest', pool=list(POOL), env=env) as leased:
        assert leased == [93, 94, 95]
        assert registry.user_domain(1234, POOL) == 96  # users skip leased domains
    assert registry.read()['leases'] == {}
    # A holder killed with -9 frees its leases: the next allocation sees it gone.
    code = ('import sys; from robot_lab.domain import lease_domains\n'
            f'with lease_domains(2, "job", pool=[97, 98], env={env!r}) as d:\n'
            '    print(d, flush=True); sys.stdin.read()')
    holder = subprocess.Popen([sys.executable, '-c', code], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout is not None
    assert holder.stdout.readline().strip() == '[97, 98]'
    with pytest.raises(RobotLabError, match='needs 1 ROS domains, 0 are free'):
        registry.lease(1, [97, 98], 'other')
    holder.send_signal(signal.SIGKILL)
    holder.wait(10)
    assert registry.lease(2, [97, 98], 'other') == [97, 98]



def test_jobs_lease_from_the_pool_the_host_gives_them(tmp_path: Path) -> None:
    """ROBOT_LAB_JOB_DOMAINS: a registry whose jobs must keep off another's part of the
    host's domains leases from its own part first, then from the user domains' top."""
    env = {**_registry_env(tmp_path / 'domains.json'), 'ROBOT_LAB_JOB_DOMAINS': '230-231'}
    with lease_domains(3, 'pytest', env=env) as leased:
        assert leased == [230, 231, 101]
    for wrong in ('230-240', 'x', '231-230'):
        bad = {**env, 'ROBOT_LAB_JOB_DOMAINS': wrong}
        with pytest.raises(RobotLabError, match=f"ROBOT_LAB_JOB_DOMAINS='{wrong}' is not"), \
                lease_domains(1, 'pytest', env=bad):
            pass

# --- real Unix users ---------------------------------------------------------------------

_skip = can_create_users()


@pytest.fixture(scope='module')
def users() -> Iterator[UnixUsers]:
    if _skip:
        pytest.skip(_skip)
    with unix_users(netns=True) as made:
        registry = made.root / 'registry'
        registry.mkdir(mode=0o1777)
        registry.chmod(0o1777)  # like /var/tmp: every user may create the file
        for short in 'abc':
            made.add(short)
        yield made
        leftovers = made.leftovers()
    assert not leftovers, f'processes outlived the test: {leftovers}'


def _env(users: UnixUsers, short: str, extra: dict[str, str]) -> dict[str, str]:
    # No daemon started by a `node list` for later: it would outlive the test (the suite's
    # rule, tests/conftest.py); the launches' own daemons answer the daemon case.
    return users.env(users.users[short], {
        **_registry_env(users.root / 'registry' / 'domains.json'),
        'ROBOT_LAB_DAEMON_AUTOSTART': '0', **extra})


def _node_list(users: UnixUsers, short: str, extra: dict[str, str],
               *flags: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        users.command(users.users[short], ['robot-lab', 'node', 'list', *flags]),
        env=_env(users, short, extra), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)


def _listed(users: UnixUsers, short: str, extra: dict[str, str]) -> list[str]:
    out, _err = _node_list(users, short, extra).communicate(timeout=60)
    return out.split()


KERNEL = """
import sys, rclpy, robot_lab
sess = robot_lab.session()
node = rclpy.create_node('kernel_a', context=sess.context)
robot_lab.wait_for_nodes(['/controller', '/robot', '/sensor'], timeout=60)
print('up', sess.domain_id, flush=True)
sys.stdin.read()
"""


@pytest.mark.parametrize('extra', [
    {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'},
    {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET'},
    {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET', 'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'},
], ids=['localhost', 'subnet', 'subnet-udp'])
def test_two_students_see_only_their_own_nodes(users: UnixUsers,
                                               extra: dict[str, str]) -> None:
    launches: list[Proc] = []
    kernel = None
    try:
        for short in 'ab':
            launches.append(Proc(users.command(users.users[short], [
                'robot-lab', 'launch', 'robot_lab', 'robot.launch.xml']),
                env=_env(users, short, extra)))
        # Student a's second session (a kernel): its own node, visible to a's commands.
        kernel = subprocess.Popen(
            users.command(users.users['a'], [sys.executable, '-c', KERNEL]),
            env=_env(users, 'a', extra), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            text=True)
        for launch in launches:
            launch.wait_for(r'Robot node started', timeout=30)
            launch.wait_for(r'Controller node started', timeout=30)
            launch.wait_for(r'Sensor node started', timeout=30)
        assert kernel.stdout is not None
        _up, domain = kernel.stdout.readline().split()
        # A kernel's node announces nothing (as a `ros2 run` node): a's warm daemon learns
        # of it by discovery alone, which a command typed at once can beat (so can ros2's
        # daemon). Wait, bounded, until a's own list has it; then take every list.
        deadline = time.monotonic() + 20
        while '/kernel_a' not in _listed(users, 'a', extra):
            assert time.monotonic() < deadline, "a's daemon never listed a's kernel node"
        lists = {(short, flags): _node_list(users, short, extra, *flags)
                 for short in 'abc' for flags in ((), ('--no-daemon',))}
        seen = {}
        for key, proc in lists.items():
            out, err = proc.communicate(timeout=60)
            assert proc.returncode == 0, err
            seen[key] = out.split()
        for flags in ((), ('--no-daemon',)):
            assert seen['a', flags] == ['/controller', '/kernel_a', '/robot', '/sensor'], flags
            assert seen['b', flags] == NODES, flags
            assert seen['c', flags] == [], flags
    finally:
        if kernel is not None:
            kernel.kill()
            kernel.wait()
        for launch in launches:
            launch.stop()
    entries = DomainRegistry(users.root / 'registry' / 'domains.json').read()['users']
    assert sorted(e['domain'] for e in entries.values()) == [93, 94, 95]
    assert int(domain) == entries[str(users.users['a'].uid)]['domain']  # the kernel's too
