"""Recording and replaying service data, as the Jazzy tutorial's *Managing Service Data* does:
`ros2 bag record --service`, `bag info`, `bag play --publish-service-requests`.

demo_nodes_cpp's introspection_service is C++ and not on PyPI; the kit's /switch (std_srvs
SetBool, with the same `service_configure_introspection` parameter) takes its role, and
`ros2 service call` the introspection_client's.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import BIN, Proc, run_cli

import robot_lab

SWITCH = [str(BIN / 'ros2'), 'run', 'robot_lab', 'switch_node']
CALLS = ['{data: true}', '{data: false}', '{data: true}']


def switch(*params: str) -> Proc:
    proc = Proc([*SWITCH, '--ros-args', *[a for p in params for a in ('-p', p)]])
    proc.wait_for('Switch node started', timeout=60)
    return proc


def robot_lines(proc: Proc, count: int = 3, timeout: float = 15.0) -> list[str]:
    """The switch's "Robot …" lines, once `count` have come or at the deadline: a request
    is answered after the server logged it, but the line still has a pipe and a reader
    thread to pass (CI: the third line was missing when the player had finished)."""
    def lines() -> list[str]:
        return [line.split(']: ', 1)[1] for line in proc.lines if '[switch]: Robot ' in line]

    deadline = time.monotonic() + timeout
    while len(lines()) < count and time.monotonic() < deadline:
        time.sleep(0.05)
    return lines()


@pytest.fixture(scope='module')
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A bag of three SetBool calls to an introspected /enable (server-side events only)."""
    where = tmp_path_factory.mktemp('service_bag')
    server = switch('service_configure_introspection:=contents')
    recorder = Proc([str(BIN / 'ros2'), 'bag', 'record', '--service', '/enable', '-o',
                     'services'], cwd=where)
    try:
        recorder.wait_for("Subscribed to topic '/enable/_service_event'", timeout=60)
        for call in CALLS:
            done = run_cli('service', 'call', '/enable', 'std_srvs/srv/SetBool', call)
            assert done.returncode == 0, done.stderr
        assert robot_lines(server) == ['Robot enabled', 'Robot disabled', 'Robot enabled']
    finally:
        recorder.stop()  # Ctrl-C
        server.stop()
    yield where / 'services'


def test_info_lists_the_recorded_service(recorded: Path) -> None:
    info = run_cli('bag', 'info', str(recorded))
    assert info.returncode == 0, info.stderr
    # each call: the server's REQUEST_RECEIVED and RESPONSE_SENT events
    assert info.stdout.endswith(
        'Service:           1\n'
        'Service information: Service: /enable | Type: std_srvs/srv/SetBool | '
        'Event Count: 6 | Serialization Format: cdr\n'), info.stdout
    verbose = run_cli('bag', 'info', '--verbose', str(recorded)).stdout
    assert ('Service: /enable | Type: std_srvs/srv/SetBool | Request Count: 3 | '
            'Response Count: 3 | Serialization Format: cdr\n') in verbose


def test_play_publish_service_requests_calls_the_live_service(recorded: Path) -> None:
    server = switch()  # a fresh /switch, disabled, introspection off
    try:
        played = run_cli('bag', 'play', '--publish-service-requests', str(recorded),
                         timeout=90)
        assert played.returncode == 0, played.stderr
        assert 'Traceback' not in played.stderr and "isn't ready" not in played.stderr
        # the player waits for each response before it exits, so the log is complete
        assert robot_lines(server) == ['Robot enabled', 'Robot disabled', 'Robot enabled']
    finally:
        server.stop()


def test_requests_from_the_clients_side_are_not_in_a_server_side_recording(
        recorded: Path) -> None:
    """`--service-requests-source client_introspection` replays REQUEST_SENT events only:
    this bag has none (the caller had no introspection), so nothing is sent."""
    server = switch()
    try:
        player = robot_lab.play(recorded, publish_service_requests=True,
                                service_requests_source='client_introspection')
        assert player.wait(60)
        assert player.counts == {'/enable/_service_event': 0}
        served = robot_lab.play(recorded, publish_service_requests=True)
        assert served.wait(60)
        assert served.counts == {'/enable/_service_event': 3}
        assert robot_lines(server) == ['Robot enabled', 'Robot disabled', 'Robot enabled']
    finally:
        server.stop()


def test_without_the_flag_the_events_are_republished(recorded: Path) -> None:
    """rosbag2's default: the `_service_event` messages play as a topic, all six."""
    from std_srvs.srv import SetBool

    from robot_lab.rclpy_session import session

    got: list[int] = []
    all_six = threading.Event()

    def take(msg: Any) -> None:
        got.append(int(msg.info.event_type))
        if len(got) == 6:
            all_six.set()

    node = session().node
    sub = node.create_subscription(SetBool.Event, '/enable/_service_event', take, 10)
    try:
        player = robot_lab.play(recorded)
        assert player.wait(60)
        assert player.counts == {'/enable/_service_event': 6}
        assert all_six.wait(10), got
    finally:
        node.destroy_subscription(sub)
    assert got == [1, 2, 1, 2, 1, 2]  # REQUEST_RECEIVED, RESPONSE_SENT per call
