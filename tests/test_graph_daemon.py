"""The graph daemon (`robot-lab daemon`, and the one `robot-lab launch` starts) and the
launchers' expected-node files: warm answers, the same text as without a daemon, and no
daemon outliving what started it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import psutil
import pytest
from conftest import BIN, reference_system, run_cli

from robot_lab.errors import GraphError
from robot_lab.graph import daemon
from robot_lab.graph.expected import expected_nodes, graph_dir

THREE = '/controller\n/robot\n/sensor\n'


def _daemon_children(pid: int) -> list[psutil.Process]:
    return [p for p in psutil.Process(pid).children(recursive=True)
            if '--robot-lab-graph-daemon' in p.cmdline()]


def _gone(pid: int, timeout: float = 10.0) -> bool:
    try:
        psutil.Process(pid).wait(timeout)
    except psutil.NoSuchProcess:
        return True
    except psutil.TimeoutExpired:
        return False
    return True


def _wait(condition, timeout: float = 10.0) -> bool:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return False


@pytest.fixture
def no_daemon() -> Iterator[None]:
    """Each test starts without a daemon on its domain and leaves none behind."""
    daemon.stop()
    yield
    daemon.stop()


def test_daemon_verbs_print_what_ros2_daemon_prints(no_daemon: None) -> None:
    assert run_cli('daemon', 'status').stdout == 'The daemon is not running\n'
    assert run_cli('daemon', 'stop').stdout == 'The daemon is not running\n'
    started = run_cli('daemon', 'start')
    assert started.stdout == 'The daemon has been started\n', started.stderr
    assert run_cli('daemon', 'status').stdout == 'The daemon is running\n'
    assert run_cli('daemon', 'start').stdout == 'The daemon is already running\n'
    pid = daemon.query('ping')['pid']
    # `ros2 daemon start` detaches it: its own session, not a child of the command
    assert os.getsid(pid) == pid
    assert run_cli('daemon', 'stop').stdout == 'The daemon has been stopped\n'
    assert _gone(pid)
    assert run_cli('daemon', 'status').stdout == 'The daemon is not running\n'
    assert not daemon.socket_path().exists()


def test_daemon_answers_like_a_session_and_survives_bad_requests(no_daemon: None) -> None:
    assert run_cli('daemon', 'start').returncode == 0
    with reference_system():
        # Nodes started with `robot-lab run` announce nothing: like ros2's daemon, this one
        # answers with what it has discovered so far, so wait until that is all three.
        assert _wait(lambda: daemon.query('node_list') == ['/controller', '/robot', '/sensor'])
        assert run_cli('node', 'list').stdout == THREE
        assert run_cli('node', 'list', '--no-daemon').stdout == THREE
        assert run_cli('node', 'list', '-c').stdout == '3\n'
        typed = run_cli('topic', 'list', '-t').stdout
        for line in ('/cmd_vel [geometry_msgs/msg/Twist]',
                     '/robot/status [std_msgs/msg/String]',
                     '/sensor/temperature [std_msgs/msg/Float32]'):
            assert line in typed.splitlines()
        assert typed == run_cli('topic', 'list', '-t', '--no-daemon').stdout
        services = run_cli('service', 'list').stdout.splitlines()
        assert '/sensor/set_parameters' in services
        hidden = daemon.query('node_list', include_hidden=True)
        assert any(name.startswith('/_robot_lab_') for name in hidden)  # its own node
        # an op this daemon does not know (a client newer than it): the client asks the
        # graph itself; a request that fails says why
        assert daemon.query('bogus') is None
        with pytest.raises(GraphError, match="Node not found: '/nobody'"):
            daemon.query('param_dump', name='/nobody')
        assert daemon.query('ping')['pid'] > 0  # still serving


def test_daemon_is_per_domain(no_daemon: None, ros_domain: int) -> None:
    assert run_cli('daemon', 'start').returncode == 0
    other = {'ROS_DOMAIN_ID': str((ros_domain + 50) % 100 + 1)}
    assert run_cli('daemon', 'status', env=other).stdout == 'The daemon is not running\n'
    assert graph_dir() != graph_dir({**os.environ, **other})


def test_daemon_is_per_network_namespace(no_daemon: None) -> None:
    """A process in another network namespace hears none of this one's nodes (a grading
    job, a second test run beside this one), so it asks its own daemon, not this one."""
    assert run_cli('daemon', 'start').returncode == 0
    there = subprocess.run(['unshare', '--net', sys.executable, '-c',
                            'from robot_lab.graph.expected import graph_dir; print(graph_dir())'],
                           capture_output=True, text=True, timeout=60, check=True)
    assert there.stdout.strip() != str(graph_dir()), there.stdout
    status = subprocess.run(['unshare', '--net', str(BIN / 'robot-lab'), 'daemon', 'status'],
                            capture_output=True, text=True, timeout=60)
    assert status.stdout == 'The daemon is not running\n', status.stdout + status.stderr


def test_idle_daemon_exits_by_itself(no_daemon: None) -> None:
    assert run_cli('daemon', 'start', '--idle-timeout', '1').returncode == 0
    pid = daemon.query('ping')['pid']
    assert _gone(pid, timeout=10)
    assert not daemon.is_running()


# A daemon that lives on for a second after closing its session, as a loaded host's does
# (an exit handler registered first runs last).
_SLOW_EXIT = """
import atexit, sys, time
from robot_lab.graph import daemon
atexit.register(time.sleep, 1.0)
sys.exit(daemon._main(['--robot-lab-graph-daemon']))
"""


@pytest.mark.parametrize('op', ['topic_info', 'node_info'])
def test_a_request_in_flight_when_the_daemon_exits_gets_no_answer(no_daemon: None,
                                                                  op: str) -> None:
    """A daemon ending while it answers (its launcher stopped, or deaf: `lost_ports`) must
    not answer from its closing session: s17's CI printed `graph daemon: InvalidHandle`
    for a `topic info`. Cut off, the command asks the graph itself (`query` is None)."""
    proc = subprocess.Popen([sys.executable, '-c', _SLOW_EXIT])
    try:
        assert daemon.wait_until_running(30, proc=proc)
        outcome: list[object] = []

        def ask() -> None:
            try:  # an unknown name keeps the daemon looking for LOOKUP_TIMEOUT (2.5 s)
                outcome.append(daemon.query(op, name='/not_there_yet', timeout=30))
            except GraphError as err:
                outcome.append(err)

        asking = threading.Thread(target=ask)
        asking.start()
        # in flight: this ping and the request
        assert _wait(lambda: daemon.query('ping')['in_flight'] >= 2)
        proc.terminate()
        asking.join(30)
        assert outcome == [None]
        assert proc.wait(30) == 0
    finally:
        proc.kill()
        proc.wait()


# A daemon whose exit hangs holding the GIL, as Fast DDS 2.14's deadlock on destroying a
# publisher does (s14T1 left one 30 minutes past its owner): an exit handler that sleeps
# in C with the GIL held, run after the daemon's own.
_HANGING_EXIT = """
import atexit, ctypes, sys
from robot_lab.graph import daemon
daemon.EXIT_WITHIN = 3.0
atexit.register(lambda: ctypes.PyDLL(None).sleep(120))
sys.exit(daemon._main(['--robot-lab-graph-daemon', '--idle-timeout', '1']))
"""


def test_a_daemon_whose_exit_hangs_is_ended_by_its_watchdog(no_daemon: None) -> None:
    # Without the watchdog the exit takes 120 s and this raises TimeoutExpired.
    done = subprocess.run([sys.executable, '-c', _HANGING_EXIT], capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 1, done.stderr
    assert 'most recent call first' in done.stderr  # where each thread was


def test_daemon_ends_with_its_owner_even_after_kill_9(no_daemon: None) -> None:
    owner = subprocess.Popen(['sleep', '600'])
    try:
        started = run_cli('daemon', 'start', '--owner', str(owner.pid))
        assert started.stdout == 'The daemon has been started\n', started.stderr
        pid = daemon.query('ping')['pid']
        owner.kill()
        owner.wait()
        assert _gone(pid)
        assert not daemon.is_running()
    finally:
        owner.kill()
        owner.wait()


def test_launch_starts_a_daemon_that_dies_with_it(no_daemon: None, start) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', 'robot_lab', 'robot.launch.xml')
    # typed right away: the launcher's socket holds the question until the answer is whole
    listed = run_cli('node', 'list')
    assert listed.stdout == THREE, (listed.stdout, listed.stderr)
    children = _daemon_children(launch.popen.pid)
    assert len(children) == 1
    assert daemon.query('ping')['pid'] == children[0].pid
    assert expected_nodes(graph_dir()) == {'/controller', '/robot', '/sensor'}
    # a second launch on the same graph uses that daemon instead of starting its own
    second = start('robot-lab', 'launch', 'robot_lab', 'robot_sim.launch.xml')
    second.wait_for(r'\[robot1\.robot\]: Robot node started', timeout=30)
    assert _daemon_children(second.popen.pid) == []
    launch.popen.send_signal(signal.SIGINT)
    assert launch.popen.wait(30) == 0
    assert _gone(children[0].pid)
    sim = {f'/robot{i}/{n}' for i in (1, 2) for n in ('controller', 'robot', 'sensor')}
    assert expected_nodes(graph_dir()) == sim
    # the daemon went with the first launch; the second starts its own within a second
    assert _wait(lambda: len(_daemon_children(second.popen.pid)) == 1)
    assert _wait(daemon.is_running)
    assert daemon.query('node_list') == sorted(sim)


def test_kill_9_of_the_launcher_takes_the_daemon_and_its_file(no_daemon: None, start) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', 'robot_lab', 'robot.launch.xml')
    launch.wait_for(r'Robot node started', timeout=30)
    assert _wait(lambda: _daemon_children(launch.popen.pid))
    (child,) = _daemon_children(launch.popen.pid)
    assert _wait(lambda: len(expected_nodes(graph_dir())) == 3)
    launch.popen.kill()
    launch.popen.wait()
    assert _gone(child.pid)
    assert not daemon.is_running()  # the socket file may be left; nobody answers on it
    assert expected_nodes(graph_dir()) == set()
    assert not list(graph_dir().glob('launch-*.json'))  # removed by that reader


def test_a_dead_node_is_no_longer_expected(start) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', 'robot_lab', 'robot.launch.xml',
                   env={daemon.NO_DAEMON_VARIABLE: '1'})
    launch.wait_for(r'Robot node started', timeout=30)
    assert _wait(lambda: len(expected_nodes(graph_dir())) == 3)
    assert _daemon_children(launch.popen.pid) == []  # ROBOT_LAB_NO_DAEMON=1
    sensor = next(p for p in psutil.Process(launch.popen.pid).children(recursive=True)
                  if '__node:=sensor' in p.cmdline())  # a forked node: the fork server's
    sensor.kill()
    launch.wait_for(r'\[sensor_node-1\]: process has died', timeout=10)
    assert expected_nodes(graph_dir()) == {'/controller', '/robot'}
    assert run_cli('node', 'list').stdout == '/controller\n/robot\n'


def test_query_without_a_daemon_is_none(no_daemon: None) -> None:
    assert daemon.query('node_list') is None


def test_a_launch_that_fails_to_start_leaves_no_expectation(tmp_path) -> None:  # type: ignore[no-untyped-def]
    bad = tmp_path / 'bad.launch.xml'
    bad.write_text('<launch>\n  <node pkg="robot_lab" exec="sensor_node" name="s"\n</launch>\n')
    # A launcher an earlier test had to kill (SIGKILL after 10 s of shutdown on a loaded
    # host) leaves its file for the next reader; this test is about the failed launch's.
    before = set(graph_dir().glob('launch-*.json'))
    failed = run_cli('launch', str(bad))
    assert failed.returncode == 1 and 'bad.launch.xml' in failed.stderr
    # removed by the launcher itself, not left for the next reader to clean up
    assert set(graph_dir().glob('launch-*.json')) - before == set()
    assert expected_nodes(graph_dir()) == set()
