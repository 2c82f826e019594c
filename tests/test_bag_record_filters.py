"""`ros2 bag record`'s selection options, as rosbag2_transport's TopicFilter decides, on the
kit's reference system: regular expressions that search, topic types, exclusions, hidden
topics, `--no-discovery`, and ros2bag's checks of the command line.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import Proc, reference_system, run_cli

import robot_lab

SYSTEM = {'/sensor/temperature', '/cmd_vel', '/robot/status'}


@pytest.fixture(scope='module')
def system(ros_domain: int) -> Iterator[dict[str, Proc]]:
    with reference_system() as procs:
        robot_lab.wait_for_nodes(['/sensor', '/controller', '/robot'], timeout=30)
        yield procs


def recorded(tmp_path: Path, name: str, *topics: str, **options: object) -> set[str]:
    """The topics a 1.5 s recording took (messages counted, so each was really heard)."""
    rec = robot_lab.record(*topics, output=tmp_path / name, duration=1.5, **options)
    assert rec.wait(60)
    rec.stop()
    return {topic for topic, n in rec.counts.items() if n}


def test_regex_searches_and_types_select(system: dict[str, Proc], tmp_path: Path) -> None:
    assert recorded(tmp_path, 'regex', regex='sensor') == {'/sensor/temperature'}
    assert recorded(tmp_path, 'types', topic_types=['geometry_msgs/msg/Twist']) == {'/cmd_vel'}
    everything = recorded(tmp_path, 'all', all_topics=True,
                          exclude_topics=['/rosout', '/parameter_events'])
    assert everything == SYSTEM
    assert recorded(tmp_path, 'excluded', all_topics=True, exclude_regex='cmd|rosout|param',
                    exclude_topic_types=['std_msgs/msg/String']) == {'/sensor/temperature'}


def test_hidden_topics_need_the_option(system: dict[str, Proc], tmp_path: Path) -> None:
    from std_msgs.msg import Int32

    from robot_lab.rclpy_session import session

    node = session().node
    publisher = node.create_publisher(Int32, '/lab/_debug', 10)
    timer = node.create_timer(0.05, lambda: publisher.publish(Int32(data=1)))
    try:
        lines: list[str] = []
        assert '/lab/_debug' not in recorded(tmp_path, 'hidden', '/lab/_debug',
                                             '/sensor/temperature', log=lines.append)
        assert any('Hidden topics are not recorded. Enable them with --include-hidden-topics'
                   in line for line in lines)
        assert '/lab/_debug' in recorded(tmp_path, 'shown', '/lab/_debug',
                                         include_hidden_topics=True)
    finally:
        node.destroy_timer(timer)
        node.destroy_publisher(publisher)


def test_no_discovery_keeps_to_the_topics_of_the_start(system: dict[str, Proc],
                                                       tmp_path: Path) -> None:
    from std_msgs.msg import Int32

    from robot_lab.rclpy_session import session

    subscribed = threading.Event()

    def log(line: str) -> None:
        if "Subscribed to topic '/sensor/temperature'" in line:
            subscribed.set()

    rec = robot_lab.record(output=tmp_path / 'fixed', all_topics=True, no_discovery=True,
                           duration=2.0, log=log)
    node = session().node
    assert subscribed.wait(30)  # the one discovery pass is over
    publisher = node.create_publisher(Int32, '/lab/late', 10)
    timer = node.create_timer(0.05, lambda: publisher.publish(Int32(data=1)))
    try:
        assert rec.wait(60)
        rec.stop()
    finally:
        node.destroy_timer(timer)
        node.destroy_publisher(publisher)
    assert '/lab/late' not in rec.counts and rec.counts['/sensor/temperature'] > 0


@pytest.mark.parametrize(('args', 'message'), [
    ((), 'Need to specify at least one option out of --all, --all-topics, --all-services, '
         '--services, --topics, --topic-types or --regex'),
    (('/cmd_vel', '--exclude-topics', '/x'),
     '--exclude-topics argument requires either --all, --all-topics, --topic-types or --regex'),
    (('--services', '/enable', '--exclude-services', '/x'),
     '--exclude-services argument requires either --all, --all-services or --regex'),
    (('/cmd_vel', '--exclude-regex', 'x'),
     '--exclude-regex argument requires either --all, --all-topics, --topic-types, '
     '--all-services or --regex'),
])
def test_command_line_checks_are_ros2bag_s(args: tuple[str, ...], message: str,
                                           tmp_path: Path) -> None:
    done = run_cli('bag', 'record', *args, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr == f'[ERROR] [ros2bag]: {message}\n'
    assert not list(tmp_path.iterdir())  # nothing written


def test_start_paused_then_space_records_from_then_on(system: dict[str, Proc],
                                                      tmp_path: Path) -> None:
    """`--start-paused` in a terminal: nothing is written until SPACE; `--custom-data`
    lands in metadata.yaml."""
    import os
    import pty
    import time

    import yaml
    from conftest import BIN
    from std_msgs.msg import Float32

    from robot_lab.rclpy_session import session

    keys, terminal = pty.openpty()
    rec = Proc([str(BIN / 'ros2'), 'bag', 'record', '/sensor/temperature', '--start-paused',
                '-o', 'paused', '--custom-data', 'lab=ch6', 'student=alice', 'lab=lab1.3'],
               env=dict(os.environ), cwd=tmp_path, stdin=terminal)
    os.close(terminal)
    try:
        rec.wait_for('Press SPACE for pausing/resuming$', timeout=60)
        rec.wait_for('Wait for recording: Press SPACE to start.$', timeout=60)
        rec.wait_for("Subscribed to topic '/sensor/temperature'", timeout=60)
        paused_from = time.time_ns()
        file = tmp_path / 'paused' / 'paused_0.mcap'
        paused_size = file.stat().st_size  # paused: the 10 Hz sensor's messages are dropped
        # Stay paused while the sensor publishes ten messages (about a second).
        heard = threading.Semaphore(0)
        node = session().node
        sub = node.create_subscription(Float32, '/sensor/temperature',
                                       lambda _msg: heard.release(), 10)
        try:
            for _ in range(10):
                assert heard.acquire(timeout=30), 'the sensor stopped publishing'
        finally:
            node.destroy_subscription(sub)
        os.write(keys, b' ')
        rec.wait_for('Resuming recording.$')
        deadline = time.monotonic() + 30  # the writer flushes every 0.5 s once it has data
        while file.stat().st_size < paused_size + 200:
            assert time.monotonic() < deadline, 'nothing written after SPACE'
            time.sleep(0.1)
    finally:
        rec.stop()  # Ctrl-C
        os.close(keys)
    meta = yaml.safe_load((tmp_path / 'paused' / 'metadata.yaml').read_text())
    info = meta['rosbag2_bagfile_information']
    assert info['custom_data'] == {'lab': 'lab1.3', 'student': 'alice'}
    assert info['message_count'] >= 1
    # Nothing from the paused second (the sensor ran all along). The first message may
    # predate SPACE by a little: one the sensor sent just before it can still wait in
    # the recorder's queue, and is written with its reception time, as rosbag2 does.
    assert info['starting_time']['nanoseconds_since_epoch'] >= paused_from + 500_000_000


def test_qos_overrides_file_decides_the_subscription(tmp_path: Path) -> None:
    """The QoS how-to's `ros2 bag record --qos-profile-overrides-path FILE`: a latched
    (transient local) message published before the recording starts is recorded under the
    adapted profile, and not when the file asks for a volatile subscription."""
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from std_msgs.msg import String

    from robot_lab.rclpy_session import session

    node = session().node
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    publisher = node.create_publisher(String, '/lab/latched', latched)
    publisher.publish(String(data='Hello World'))
    overrides = tmp_path / 'durability_override.yaml'
    overrides.write_text('/lab/latched:\n  durability: volatile\n  history: keep_all\n')
    try:
        lines: list[str] = []
        assert recorded(tmp_path, 'adapted', '/lab/latched') == {'/lab/latched'}
        assert recorded(tmp_path, 'overridden', '/lab/latched', qos_overrides=overrides,
                        log=lines.append) == set()
        assert any('Overriding subscription profile for /lab/latched' in line
                   for line in lines)
    finally:
        node.destroy_publisher(publisher)
