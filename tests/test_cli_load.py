"""Graph verbs on a loaded host: fresh CLI processes, cold (no daemon) or answered by a warm
daemon, print the whole graph while busy loops hold every core (issue 22: a cold
`action list -t` once printed an empty list in CI)."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import pytest
from conftest import Proc, run_cli

import robot_lab
from robot_lab.graph import daemon

BIN = os.path.dirname(sys.executable)
FIBONACCI = '/fibonacci [test_msgs/action/Fibonacci]\n'


@pytest.fixture(scope='module')
def busy_host() -> Iterator[None]:
    """An action server and a service server up, then one busy loop per core."""
    run = [os.path.join(BIN, 'robot-lab'), 'run', 'robot_lab']
    servers = [Proc([*run, 'fibonacci_node']), Proc([*run, 'switch_node'])]
    busy: list[subprocess.Popen[bytes]] = []
    try:
        servers[0].wait_for('Fibonacci action server started', timeout=60)
        servers[1].wait_for('Switch node started', timeout=60)
        robot_lab.wait_for_nodes(['/fibonacci_action_server', '/switch'], timeout=30)
        busy = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
                for _ in range(os.cpu_count() or 2)]
        yield
    finally:
        for proc in busy:
            proc.kill()
            proc.wait()
        for server in servers:
            server.stop()
        daemon.stop()


def _cold(*args: str) -> str:
    result = run_cli(*args, env={'ROBOT_LAB_NO_DAEMON': '1'})
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_cold_action_list_under_load_is_complete(busy_host: None) -> None:
    """Four fresh participants at once, as the tutorial batch started them, each cold."""
    daemon.stop()
    with ThreadPoolExecutor(4) as pool:
        answers = list(pool.map(lambda _: _cold('action', 'list', '-t'), range(4)))
    assert answers == [FIBONACCI] * 4


def test_cold_lists_wait_for_the_nodes_endpoints(busy_host: None) -> None:
    with ThreadPoolExecutor(3) as pool:
        nodes, services, actions = pool.map(lambda args: _cold(*args), [
            ('node', 'list'), ('service', 'list'), ('action', 'list')])
    assert nodes == '/fibonacci_action_server\n/switch\n'
    assert '/enable\n' in services and '/get_state\n' in services
    assert actions == '/fibonacci\n'


def test_warm_daemon_answers_action_and_info_verbs(busy_host: None) -> None:
    assert run_cli('daemon', 'start').returncode == 0
    try:
        ping = daemon.query('ping')
        assert ping is not None
        assert daemon.query('action_list') == [['/fibonacci', ['test_msgs/action/Fibonacci']]]
        assert run_cli('action', 'list', '-t').stdout == FIBONACCI
        info = run_cli('action', 'info', '/fibonacci').stdout
        assert info == ('Action: /fibonacci\nAction clients: 0\nAction servers: 1\n'
                        '    /fibonacci_action_server\n')
        node = run_cli('node', 'info', '/fibonacci_action_server').stdout
        assert node.endswith('  Action Servers:\n    /fibonacci: test_msgs/action/Fibonacci\n'
                             '  Action Clients:\n\n')
        service = run_cli('service', 'info', '/enable').stdout
        assert service == 'Type: std_srvs/srv/SetBool\nClients count: 0\nServices count: 1\n'
        topic = run_cli('topic', 'info', '/rosout', '-v').stdout
        assert topic.count('Node name: fibonacci_action_server') == 1
        # The daemon answered: the same text as each verb's own session prints.
        assert _cold('action', 'info', '/fibonacci') == info
        assert _cold('service', 'info', '/enable') == service
        unknown = run_cli('node', 'info', '/nobody')
        assert unknown.returncode != 0 and "Unable to find node '/nobody'" in unknown.stderr
        assert daemon.query('ping')['pid'] == ping['pid']  # the error did not end it
    finally:
        daemon.stop()
