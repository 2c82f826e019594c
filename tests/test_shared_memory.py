"""A killed participant's shared-memory segment is swept; a live one's is never touched; a
live one whose port Fast DDS took over is named, and the graph daemon so struck exits.

The kit's own profile keeps its participants off shared-memory ports (test_env), so a
take-over strikes only processes run with a profile of the user's own: these tests run so."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import users_profile

from robot_lab.domain import domain_ports
from robot_lab.graph import daemon
from robot_lab.pkg.doctor import doctor
from robot_lab.process import stop
from robot_lab.shared_memory import (
    HEARING_CHECK,
    deaf_processes,
    listening_ports,
    lost_ports,
    sweep_dead_segments,
)


@pytest.fixture(autouse=True)
def _users_profile(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """These tests run with a profile of the user's own (see the module's docstring)."""
    monkeypatch.setenv('FASTRTPS_DEFAULT_PROFILES_FILE', str(users_profile(tmp_path)))


# A node that publishes once (Fast DDS maps its segment when it has data to send), says so,
# and stays. Stopped with the launcher's SIGINT -> SIGTERM -> SIGKILL (process.stop): a bare
# rclpy process starved on a loaded host and sent SIGINT early in `spin` can miss the wake-up
# or hang in interpreter exit (s32A6: still spinning 30 s after SIGINT; 4 of 120 starved
# probes here), which is rclpy's, not what these tests check.
NODE = """
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('shm_probe')
node.create_publisher(String, 'shm_probe', 10).publish(String(data='x'))
print('up', flush=True)
rclpy.spin(node)
"""


def _own_segments(pid: int) -> set[Path]:
    """The Fast DDS segments process `pid` made: of those it maps (a peer's too, once it has
    heard from one), the ones whose lock file it holds (/proc/locks: pid, then dev:inode)."""
    held = set()
    for line in Path('/proc/locks').read_text().splitlines():
        fields = line.split()
        fields = fields[2:] if fields[1] == '->' else fields[1:]  # '->': waiting for it
        if len(fields) > 4 and fields[3] == str(pid):
            held.add(int(fields[4].rsplit(':', 1)[1]))
    found = set()
    for name in re.findall(r'(/dev/shm/fastrtps_[0-9a-f]{16})$',
                           Path(f'/proc/{pid}/maps').read_text(), re.M):
        with contextlib.suppress(FileNotFoundError):
            if os.stat(f'{name}_el').st_ino in held:
                found.add(Path(name))
    return found


def _start() -> tuple[subprocess.Popen[str], set[Path]]:
    proc = subprocess.Popen([sys.executable, '-c', NODE], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline() == 'up\n'
    deadline = time.monotonic() + 10
    while not (segments := _own_segments(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.05)  # polling /proc: the mapping has no event to wait on
    assert segments, 'the node mapped no shared-memory segment'
    return proc, segments


def test_a_killed_nodes_segment_is_swept_and_a_live_ones_kept() -> None:
    killed, dead = _start()
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    live, kept = _start()
    try:
        assert dead.isdisjoint(kept)
        assert all(p.exists() and Path(f'{p}_el').exists() for p in dead)  # what -9 leaves
        sweep_dead_segments()  # too young to judge (a lock file is made, then locked)
        assert all(p.exists() for p in dead)
        # Aged by hand, not by waiting; a sweep with no minimum age could take another
        # test's participant between making its lock file and locking it.
        hour_ago = time.time() - 3600
        for path in dead:
            os.utime(f'{path}_el', (hour_ago, hour_ago))
        swept = sweep_dead_segments()
        assert swept.segments >= len(dead) and swept.bytes > 0
        assert not any(p.exists() or Path(f'{p}_el').exists() for p in dead)
        assert all(p.exists() and Path(f'{p}_el').exists() for p in kept)
        assert live.poll() is None
    finally:
        stop(live)
    assert not any(p.exists() for p in kept)  # a clean exit removes its own


def _dead_segment(age: float = 3600) -> Path:
    """A segment as a killed participant leaves it: the file, and its lock file unlocked."""
    segment = Path(f'/dev/shm/fastrtps_{os.urandom(8).hex()}')
    segment.write_bytes(b'\0' * 4096)
    lock = Path(f'{segment}_el')
    lock.touch()
    then = time.time() - age
    os.utime(lock, (then, then))
    return segment


def test_a_launch_that_ends_and_a_lessons_setup_sweep(tmp_path: Path) -> None:
    launch = tmp_path / 'one.launch.xml'
    launch.write_text('<launch><executable cmd="true" output="screen"/></launch>\n')
    first = _dead_segment()
    done = subprocess.run([str(Path(sys.executable).parent / 'robot-lab'), 'launch', str(launch)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert not first.exists() and not Path(f'{first}_el').exists()
    second = _dead_segment()
    young = _dead_segment(age=0)
    setup = "from robot_lab.grading.course import setup; setup('01_create_package')"
    done = subprocess.run([sys.executable, '-c', setup], capture_output=True, text=True,
                          timeout=60, env={**os.environ, 'ROBOT_LAB_WORKSPACE': str(tmp_path)})
    assert done.returncode == 0, done.stderr
    assert not second.exists()
    assert young.exists()  # made an instant ago: perhaps a participant about to lock it
    young.unlink()
    Path(f'{young}_el').unlink()


def _own_ports(pid: int) -> set[int]:
    """The ports `pid` listens on (it holds their lock files open), of this test's domain
    only: ports below 7400 + 250 * domain (7000 and up) are scanned by every new participant
    of the host, which would log an error on the one taken over here."""
    return listening_ports(pid) & set(domain_ports(int(os.environ['ROS_DOMAIN_ID'])))


def _take_over(port: int) -> None:
    """What a take-over leaves (s16L2; Fast DDS issues 5737, 6117): the port's file gone
    while its owner lives (a writer then makes a new one that nobody reads)."""
    Path(f'/dev/shm/fastrtps_port{port}').unlink()


def test_a_participant_whose_port_was_taken_over_is_named() -> None:
    proc, _segments = _start()
    try:
        ports = _own_ports(proc.pid)
        assert ports, 'the node listens on no port of its domain'
        assert lost_ports(proc.pid) == []
        domain = int(os.environ['ROS_DOMAIN_ID'])
        assert proc.pid not in [pid for pid, _, _ in deaf_processes(domain)]
        port = min(ports)
        _take_over(port)
        assert lost_ports(proc.pid) == [port]
        assert [(pid, lost) for pid, _, lost in deaf_processes(domain) if pid == proc.pid] == \
            [(proc.pid, [port])]
        # another domain's doctor does not list it (nor a test's deaf process another's)
        assert proc.pid not in [pid for pid, _, _ in deaf_processes((domain + 1) % 100)]
        (named,) = [c for c in doctor().checks if c.name == f'process {proc.pid}']
        assert not named.ok and f'port {port}' in named.detail and 'Restart' in str(named.fix)
    finally:
        stop(proc)


def test_a_daemon_whose_port_was_taken_over_exits() -> None:
    served = subprocess.Popen([sys.executable, '-m', 'robot_lab.graph.daemon',
                               '--robot-lab-graph-daemon', '--idle-timeout', '300'],
                              stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not (ports := _own_ports(served.pid)) and served.poll() is None \
                and time.monotonic() < deadline:
            time.sleep(0.05)  # polling /proc: the session's start has no event to wait on
        assert ports and daemon.is_running(), 'the daemon never listened'
        _take_over(min(ports))
        code = served.wait(10 * HEARING_CHECK)
    finally:
        if served.poll() is None:
            served.kill()
            served.wait()
    assert served.stderr is not None
    said = served.stderr.read()
    assert code == 0 and 'no longer hearing new participants' in said, said
    assert not daemon.is_running()


def test_a_launch_says_which_node_no_longer_hears(start) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', 'robot_lab', 'robot.launch.xml')
    pid = int(launch.wait_for(r'\[sensor_node-1\]: process started with pid \[(\d+)\]',
                              timeout=30)[1])
    launch.wait_for(r'Sensor node started', timeout=30)
    deadline = time.monotonic() + 30
    while not (ports := _own_ports(pid)) and time.monotonic() < deadline:
        time.sleep(0.05)  # polling /proc: the node's ports have no event to wait on
    assert ports, 'the sensor listens on no port of its domain'
    _take_over(min(ports))
    said = launch.wait_for(r'\[WARNING\] \[sensor_node-1\]: no longer hears .*port (\d+)',
                           timeout=10 * HEARING_CHECK)
    assert int(said[1]) == min(ports)


# A process whose own session is struck: a failed check names that as the fix.
DEAF_CHECK = """
import os, time
from pathlib import Path
from robot_lab.grading import check
from robot_lab.domain import domain_ports
from robot_lab.rclpy_session import session
from robot_lab.shared_memory import listening_ports

session()
domain = set(domain_ports(int(os.environ['ROS_DOMAIN_ID'])))
deadline = time.monotonic() + 30
while not (ports := listening_ports() & domain) and time.monotonic() < deadline:
    time.sleep(0.05)  # polling /proc: the session's ports have no event to wait on
for mode in ('hearing', 'deaf'):
    if mode == 'deaf':
        Path(f'/dev/shm/fastrtps_port{min(ports)}').unlink()
    try:
        check.eventually(lambda: False, 'something that never holds', timeout=0,
                         hint='the usual hint')
    except check.CheckError as err:
        print(mode, err.hint, flush=True)
"""


def test_a_check_in_a_process_that_no_longer_hears_says_so() -> None:
    done = subprocess.run([sys.executable, '-c', DEAF_CHECK], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    hearing, deaf = done.stdout.splitlines()
    assert hearing == 'hearing the usual hint'
    assert deaf.startswith('deaf this process no longer hears ROS participants') \
        and 'Restart Kernel' in deaf, deaf
