"""`node list` is never stale: nodes that end leave it within 3 s, whoever ended them
(the launcher stopped, the launcher or a kernel killed with -9), a warm daemon that saw
them never lists them again, and nothing is listed twice.

"Within 3 s" is the acceptance line of issue 14.5: a node killed hard is removed when its
participant's lease (2 s in the kit's Fast DDS profile) runs out. Each check records when
the first `node list` that printed no nodes was started.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, Proc, run_cli

from robot_lab.graph import daemon
from robot_lab.graph.stale_names import StaleNames

NODES = ['/controller', '/robot', '/sensor']
LEAVE_WITHIN = 3.0


@pytest.fixture(scope='module')
def warm_daemon() -> Iterator[None]:
    """A long-lived daemon on this module's domain, as `./kit lab` keeps one."""
    daemon.stop()
    started = run_cli('daemon', 'start', '--idle-timeout', '120')
    assert started.stdout == 'The daemon has been started\n', started.stderr
    yield
    daemon.stop()


def _listed(*flags: str) -> list[str]:
    result = run_cli('node', 'list', *flags)
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


def _seconds_until_empty(ended: float, *flags: str) -> float:
    """When (after `ended`) the first `node list` that printed nothing was started."""
    while True:
        asked = time.monotonic()
        if not _listed(*flags):
            return asked - ended
        if asked - ended > 30:
            raise AssertionError(f'nodes still listed 30 s after they ended: {_listed()}')


def _launch() -> Proc:
    proc = Proc([str(BIN / 'robot-lab'), 'launch', 'robot_lab', 'robot.launch.xml'])
    for line in ('Sensor node started', 'Controller node started', 'Robot node started'):
        proc.wait_for(line, timeout=30)
    return proc


def test_launch_rounds_stop_and_kill_9(warm_daemon: None) -> None:
    for ending in ('stop', 'kill'):
        launch = _launch()
        try:
            assert _listed() == NODES  # the warm daemon: exactly three, no duplicates
            if ending == 'kill':
                launch.popen.send_signal(signal.SIGKILL)
            else:
                launch.popen.send_signal(signal.SIGINT)
            launch.popen.wait(20)
            ended = time.monotonic()
        finally:
            launch.stop()
        took = _seconds_until_empty(ended)
        assert took <= LEAVE_WITHIN, f'{ending}: listed for {took:.2f} s'
    assert _listed('--no-daemon') == []


KERNEL = """
import sys, robot_lab
system = robot_lab.launch('robot_lab', 'robot.launch.xml')
robot_lab.wait_for_nodes(['/sensor', '/controller', '/robot'])
print('up', flush=True)
sys.stdin.read()
"""


def test_a_kernel_killed_with_9_takes_its_nodes_out_of_the_list(warm_daemon: None) -> None:
    kernel = subprocess.Popen([sys.executable, '-c', KERNEL], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert kernel.stdout is not None
        assert kernel.stdout.readline().strip() == 'up'
        assert _listed() == NODES
        kernel.kill()
        kernel.wait(20)
        ended = time.monotonic()
    finally:
        kernel.kill()
        kernel.wait()
    took = _seconds_until_empty(ended)
    assert took <= LEAVE_WITHIN, f'listed for {took:.2f} s after the kernel died'
    # ... and the next launch is listed once, not beside leftovers of the last.
    launch = _launch()
    try:
        listed = _listed()
    finally:
        launch.stop()
    # Listed at once beside the killed kernel's ghosts (it once printed only ['/sensor']:
    # a name with a stale entry was hidden until the new node's endpoints arrived).
    assert listed == NODES


def test_stale_names_are_dropped_after_a_grace_period() -> None:
    """The daemon's guard against rmw's resurrected participants (ros2/ros2#1413)."""
    stale = StaleNames(stale_after=2.5)
    listed = ['/controller', '/robot', '/robot', '/sensor']
    live = {'/controller': 1, '/robot': 1}  # /sensor has no endpoints, /robot one of two
    # Just discovered (names before endpoints): listed as the graph has them.
    assert stale.filter(listed, live, now=100.0) == listed
    assert stale.filter(listed, live, now=102.0) == listed
    # Still short 2.5 s later: stale entries go, the live /robot stays once.
    assert stale.filter(listed, live, now=102.6) == ['/controller', '/robot']
    # A name that gets its endpoints back is listed again at once.
    assert stale.filter(listed, {**live, '/sensor': 1}, now=103.0) == [
        '/controller', '/robot', '/sensor']
    # A real new node whose endpoints arrive late is not hidden meanwhile.
    assert stale.filter(['/new'], {}, now=200.0) == ['/new']
    assert stale.filter(['/new'], {'/new': 1}, now=202.6) == ['/new']
    # The same nodes launched again beside ghosts of the last run (a kernel killed with
    # -9): each listed once at once, before their endpoints arrive, and after they do.
    ghosts = StaleNames(stale_after=2.5)
    assert ghosts.filter(['/a', '/b'], {}, now=300.0) == ['/a', '/b']
    assert ghosts.filter(['/a', '/b'], {}, now=303.0) == []
    assert ghosts.filter(['/a', '/a', '/b', '/b'], {}, now=310.0) == ['/a', '/b']
    assert ghosts.filter(['/a', '/a', '/b', '/b'], {'/a': 1}, now=310.2) == ['/a', '/b']
    assert ghosts.filter(['/a', '/a', '/b', '/b'], {'/a': 1, '/b': 1}, now=313.0) == [
        '/a', '/b']
    # ... and when they end, nothing is listed again.
    assert ghosts.filter(['/a', '/b'], {}, now=320.0) == []


def test_a_name_a_live_launcher_vouches_for_is_never_hidden(tmp_path, monkeypatch) -> None:
    """The stale-name guesses yield to a running launcher: a ghost of /robot that left the
    list as the new /robot came (no endpoints yet) must not hide the new one."""
    from robot_lab.graph.expected import LaunchAnnouncement

    server = daemon._Server(idle_timeout=60)
    server.graph = tmp_path
    monkeypatch.setattr(server, '_live', lambda: ({'/controller': 1}, {}))
    server.stale = StaleNames(stale_after=2.5)
    server.stale.filter(['/controller', '/robot'], {'/controller': 1}, now=time.monotonic() - 9)
    assert server.current_nodes(['/controller', '/robot']) == ['/controller']  # a ghost
    announcement = LaunchAnnouncement(tmp_path)
    announcement.update([('/controller', os.getpid()), ('/robot', os.getpid())])
    try:
        assert server.current_nodes(['/controller', '/robot']) == ['/controller', '/robot']
        assert server.current_nodes(['/controller']) == ['/controller']  # nothing invented
    finally:
        announcement.close()


def test_per_node_queries_wait_for_endpoints_tied_to_a_node(tmp_path, monkeypatch) -> None:
    """CI once printed `Action servers: 0` for a live server: the server's node was known,
    its endpoints were seen, but the message tying them to it had not arrived."""
    from types import SimpleNamespace

    from robot_lab.graph.discovery import UNKNOWN_NODE, endpoints_attributed

    monkeypatch.setenv('XDG_RUNTIME_DIR', str(tmp_path))  # no launch announces nodes
    owner = {'/fibonacci/_action/status': UNKNOWN_NODE}
    node = SimpleNamespace(
        get_topic_names_and_types=lambda: [(t, ['x']) for t in owner],
        get_publishers_info_by_topic=lambda t: [SimpleNamespace(node_name=owner[t])],
        get_subscriptions_info_by_topic=lambda t: [],
    )
    ready = endpoints_attributed(SimpleNamespace(node=node, domain_id=0))  # type: ignore
    assert ready() is False  # keep waiting, up to EXPECTED_TIMEOUT
    owner['/fibonacci/_action/status'] = 'fibonacci_action_server'
    assert ready() is None  # as without a launch: the usual window and settling
    # `topic info -v` waits for its own topic's endpoints only (CI once printed a
    # publisher of /cmd_vel as `Node name: _NODE_NAME_UNKNOWN_`)
    owner['/cmd_vel'] = UNKNOWN_NODE
    one = endpoints_attributed(SimpleNamespace(node=node, domain_id=0),  # type: ignore
                               '/fibonacci/_action/status')
    assert one() is None and ready() is False
    owner['/cmd_vel'] = 'controller'
    assert ready() is None


def test_a_command_without_a_daemon_starts_one_for_the_next() -> None:
    """ros2cli's behaviour: a command that found no daemon leaves one for the next command.

    The daemon belongs to the command's session (its terminal), so the command runs here in
    a session of its own whose leader lives until the test closes its stdin: the test does
    not depend on the session pytest was started in (a CI runner's may be PID 1 or gone).
    """
    daemon.stop()
    autostart = {'ROBOT_LAB_DAEMON_AUTOSTART': '1'}  # the suite turns it off
    assert run_cli('node', 'list', '--no-daemon', env=autostart).stdout == ''
    assert not daemon.is_running()  # --no-daemon: neither uses nor spawns one (ros2cli)
    script = f'{BIN / "robot-lab"} node list; echo "exit $?"; exec cat >/dev/null'
    terminal = subprocess.Popen(
        ['sh', '-c', script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
        env={**os.environ, **autostart}, start_new_session=True)
    try:
        assert terminal.stdout is not None and terminal.stdin is not None
        assert terminal.stdout.readline() == 'exit 0\n'  # printed no nodes, succeeded
        assert daemon.wait_until_running(timeout=20)
        assert daemon.query('ping') is not None
        terminal.stdin.close()  # the terminal closes: its daemon follows
        assert terminal.wait(timeout=10) == 0
        deadline = time.monotonic() + 20
        while daemon.is_running() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not daemon.is_running()
    finally:
        if terminal.poll() is None:
            terminal.kill()
        daemon.stop()


def test_a_lessons_kernel_keeps_a_daemon_for_its_commands_and_takes_it_along(
        tmp_path: Path) -> None:
    """A notebook's `!ros2 …` runs in a session of its own (IPython's pseudo-terminal) that
    ends with the command: a daemon it started ended at once, and every command in a
    lesson was cold. The lesson's set-up starts one that serves its `!` commands and ends
    with the kernel, even a kernel killed with -9."""
    from jupyter_client.manager import start_new_kernel

    daemon.stop()
    lesson = 5  # setup() puts lesson 05 on base + 5: this module's domain
    env = {**os.environ, 'ROBOT_LAB_DAEMON_AUTOSTART': '1', 'ROBOT_LAB_HEADLESS': '1',
           'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE': str(int(os.environ['ROS_DOMAIN_ID']) - lesson),
           'ROBOT_LAB_WORKSPACE': str(tmp_path)}
    manager, client = start_new_kernel(kernel_name='robot_lab', startup_timeout=60, env=env)
    try:
        printed: list[str] = []
        client.execute_interactive(
            "from robot_lab.grading import setup\nlesson = setup('05_inspect_and_verify')\n"
            "!ros2 node list --all\n!ros2 node list --all",
            timeout=60, output_hook=lambda msg: printed.append(
                msg['content'].get('text', '') if msg['msg_type'] == 'stream' else ''))
        assert '/_robot_lab_' in ''.join(printed), printed  # the daemon's own node
        assert daemon.wait_until_running(timeout=20)
        assert daemon.query('ping')['answered'].get('node_list', 0) >= 2
        kernel = manager.provisioner.pid  # type: ignore[union-attr]
        os.kill(kernel, signal.SIGKILL)
        deadline = time.monotonic() + 20
        while daemon.is_running() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not daemon.is_running()  # it ended with its kernel
    finally:
        manager.shutdown_kernel(now=True)
        daemon.stop()


def test_action_answers_wait_for_the_servers_services(tmp_path, monkeypatch) -> None:
    """CI printed `Action servers: 0` for a live server even after cebd99a: its status
    topic was tied to the node, its send_goal service not yet. A status publisher with no
    server found (or a status reader with no client) keeps `action info` and `node info`
    waiting; the answer comes once the services arrive."""
    import time
    from types import SimpleNamespace

    import rclpy.action.graph as action_graph

    from robot_lab.graph.actions import action_info
    from robot_lab.graph.nodes import node_info

    monkeypatch.setenv('XDG_RUNTIME_DIR', str(tmp_path))  # no launch announces nodes
    arrives = time.monotonic() + 0.6  # the server's services, 0.6 s from now
    status = '/fibonacci/_action/status'
    kind = ['test_msgs/action/Fibonacci']

    def servers(_node: object, name: str, _ns: str) -> list[tuple[str, list[str]]]:
        late = time.monotonic() < arrives
        return [] if late or name != 'fibonacci_action_server' else [('/fibonacci', kind)]

    monkeypatch.setattr(action_graph, 'get_action_server_names_and_types_by_node', servers)
    monkeypatch.setattr(action_graph, 'get_action_client_names_and_types_by_node',
                        lambda *_: [])
    node = SimpleNamespace(
        get_node_names_and_namespaces=lambda: [('fibonacci_action_server', '/')],
        get_topic_names_and_types=lambda: [(status, ['action_msgs/msg/GoalStatusArray'])],
        get_publishers_info_by_topic=lambda t: [
            SimpleNamespace(node_name='fibonacci_action_server')],
        get_subscriptions_info_by_topic=lambda t: [],
        count_publishers=lambda t: 1 if t == status else 0,
        count_subscribers=lambda t: 0,
        get_publisher_names_and_types_by_node=lambda n, ns: [(status, ['x'])],
        get_subscriber_names_and_types_by_node=lambda n, ns: [],
        get_service_names_and_types_by_node=lambda n, ns: [],
        get_client_names_and_types_by_node=lambda n, ns: [],
    )
    warm = SimpleNamespace(node=node, domain_id=0, created=time.monotonic() - 60)
    info = action_info('/fibonacci', session=warm)  # type: ignore[arg-type]
    assert time.monotonic() >= arrives
    assert info.servers == [('/fibonacci_action_server', kind)]
    arrives = time.monotonic() + 0.6
    from rclpy.node import Node

    for method in ('get_publisher_names_and_types_by_node',
                   'get_subscriber_names_and_types_by_node',
                   'get_service_names_and_types_by_node', 'get_client_names_and_types_by_node'):
        monkeypatch.setattr(Node, method, lambda self, n, ns, m=method: getattr(node, m)(n, ns))
    shown = node_info('/fibonacci_action_server', session=warm)  # type: ignore[arg-type]
    assert shown.action_servers == [('/fibonacci', kind)]


def test_a_live_node_sharing_pid_bits_with_an_ended_one_stays_live(monkeypatch) -> None:
    """pids 70000 and 4464 share their low 16 bits (all a GUID carries): the instance of
    live 4464 is not counted as ended 70000's, whose instance has left the graph."""
    from robot_lab.graph import nodes

    server = daemon._Server(idle_timeout=60)
    server.announced = {('/robot', 70000): 0.0, ('/robot', 4464): 0.0, ('/cam', 70000): 0.0}
    monkeypatch.setattr(daemon, 'process_running', lambda pid: pid == 4464)
    monkeypatch.setattr(nodes, 'node_instances', lambda session: {'/robot': [4464]})
    assert server._live() == ({'/robot': 1}, {'/robot': 0})
    monkeypatch.setattr(nodes, 'node_instances', lambda session: {'/robot': [4464, 4464]})
    assert server._live() == ({'/robot': 1}, {'/robot': 1})  # the ended one's, not yet gone
    monkeypatch.setattr(nodes, 'node_instances', lambda session: {'/cam': [4464, 4464]})
    assert server._live() == ({'/cam': 0}, {'/cam': 2})  # as before: bits of an ended /cam
