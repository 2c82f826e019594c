"""`ros2 topic bw|delay|find` and `topic pub`'s QoS, wait and stamp options, with real
publishers (the kit's own `topic pub`) and ros2topic's output formats (Jazzy)."""

from __future__ import annotations

import re
import subprocess
import time
from collections.abc import Iterator

import pytest
from conftest import BIN, Proc, cli_ok_all, run_cli, venv_env

import robot_lab
from robot_lab.errors import GraphError


def pub(*args: str) -> Proc:
    return Proc([str(BIN / 'robot-lab'), 'topic', 'pub', *args])


@pytest.fixture(scope='module')
def pose(ros_domain: int) -> Iterator[Proc]:
    """/pose: PoseStamped with `header: auto` at 20 Hz, best-effort, depth 3."""
    proc = pub('-r', '20', '--qos-reliability', 'best_effort', '--qos-depth', '3',
               '/pose', 'geometry_msgs/msg/PoseStamped',
               '{header: auto, pose: {position: {x: 1.5}}}')
    try:
        proc.wait_for('publishing #2', timeout=20)
        robot_lab.wait_for_topic('/pose', timeout=10)
        yield proc
    finally:
        proc.stop()


def test_bw_delay_find_info(pose: Proc) -> None:
    from geometry_msgs.msg import PoseStamped
    from rclpy.serialization import serialize_message

    bw, delay, found, count, info = cli_ok_all(
        ('topic', 'bw', '/pose', '--duration', '2.5'),
        ('topic', 'delay', '/pose', '--duration', '2.5'),
        ('topic', 'find', 'geometry_msgs/msg/PoseStamped'),
        ('topic', 'find', '-c', 'geometry_msgs/msg/PoseStamped'),
        ('topic', 'info', '-v', '/pose'))
    # Every message has one size: its CDR serialization (empty frame_id).
    size = len(serialize_message(PoseStamped()))
    lines = bw.splitlines()
    assert lines[0] == 'Subscribed to [/pose]'
    assert len(lines) >= 3, bw
    rate = re.fullmatch(r'(\d+\.\d\d) KB/s from (\d+) messages', lines[1])
    assert rate is not None, bw
    # 20 Hz of `size` bytes (1000 B/s or more: ros2cli prints KB, sizes in KB too), give
    # or take the first interval and a loaded machine
    assert 0.5 * 20 * size < 1000 * float(rate.group(1)) < 1.5 * 20 * size
    kb = f'{size / 1000:.2f} KB'
    assert lines[2] == f'\tMessage size mean: {kb} min: {kb} max: {kb}'

    blocks = re.findall(r'average delay: (\d+\.\d{3})\n\tmin: (\d+\.\d{3})s max: '
                        r'(\d+\.\d{3})s std dev: \d+\.\d{5}s window: (\d+)\n', delay)
    assert blocks, delay
    mean, low, high, window = blocks[-1]
    # header: auto is stamped at each publish, so a message is milliseconds old on arrival
    assert float(low) <= float(mean) <= float(high) < 0.5 and int(window) >= 10

    assert (found, count) == ('/pose\n', '1\n')
    # (DDS does not carry a remote writer's history depth: rmw says UNKNOWN, as on ROS 2)
    assert 'Reliability: BEST_EFFORT' in info and 'Durability: VOLATILE' in info


def test_pub_times_waits_for_a_subscriber_and_restamps(pose: Proc) -> None:
    # -t 3: waits for one matching subscription (ros2cli's default for --times), then
    # publishes three; `stamp: now` is the time of each publish.
    proc = pub('-t', '3', '-r', '10', '/point', 'geometry_msgs/msg/PointStamped',
               '{header: {stamp: now, frame_id: base}, point: {x: 2.0}}')
    try:
        proc.wait_for(r'Waiting for at least 1 matching subscription\(s\)\.\.\.')
        before = time.time()
        # pub (as ros2cli's) starts once its writer has matched the reader; the reader may
        # match the writer a moment later, and a volatile reader drops what came before
        # (a loaded CI host lost the first of three). Two of them show the restamping.
        got = robot_lab.echo('/point', count=2, timeout=20,
                             msg_type='geometry_msgs/msg/PointStamped')
        assert proc.popen.wait(timeout=20) == 0
    finally:
        proc.stop()
    assert 'publisher: beginning loop' in proc.output
    assert proc.output.count('publishing #') == 3
    stamps = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in got]
    assert [m.header.frame_id for m in got] == ['base'] * 2
    assert all(before - 1.0 < s < time.time() for s in stamps)
    assert stamps[0] < stamps[1]  # restamped, 0.1 s apart


def test_pub_once_transient_local_reaches_a_late_subscriber(pose: Proc) -> None:
    # -w 0: no waiting; a transient-local publisher keeps the message for a subscriber
    # that comes later (while it lives: --keep-alive).
    proc = pub('--once', '-w', '0', '--keep-alive', '8', '--qos-profile', 'system_default',
               '--qos-durability', 'transient_local', '--qos-reliability', 'reliable',
               '/latched', 'std_msgs/msg/String', '{data: kept}')
    try:
        proc.wait_for('publishing #1')
        robot_lab.wait_for_topic('/latched', timeout=10)
        late = robot_lab.echo('/latched', count=1, timeout=10)  # subscribes only now
        with pytest.raises(GraphError, match='msg does not have header'):
            robot_lab.topic_delay('/latched', duration=0.1)  # a String has no stamp
    finally:
        proc.stop()
    assert 'Waiting for' not in proc.output
    assert late[0].data == 'kept'
    # Echoing a reliable transient-local topic must not change rclpy's shared sensor-data
    # preset: every plot and meter of the process subscribes with it (they went deaf).
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy, qos_profile_sensor_data
    assert qos_profile_sensor_data.durability == DurabilityPolicy.VOLATILE
    assert qos_profile_sensor_data.reliability == ReliabilityPolicy.BEST_EFFORT


def test_pub_errors_are_one_line(pose: Proc) -> None:
    bad = run_cli('topic', 'pub', '--once', '/x', 'std_msgs/msg/Header', '{stamp: yesterday}')
    assert bad.returncode == 1 and 'Traceback' not in bad.stderr
    assert "Failed to populate field 'stamp'" in bad.stderr


def test_kill_int_stops_a_background_echo(ros_domain: int) -> None:
    """bash starts a script's background jobs with SIGINT ignored; ros2cli's verbs take it
    back (in rclpy.init), so `ros2 topic echo … &` then `kill -INT %1; wait` ends. The kit's
    echo kept it ignored, and the script's `wait` hung for ever."""
    script = ('ros2 topic echo /nobody_publishes std_msgs/msg/String &\n'
              'until ros2 topic info /nobody_publishes | grep -q "Subscription count: 1"; do\n'
              '  sleep 0.1\n'
              'done\n'
              'kill -INT %1; wait %1; echo "exit $?"\n')
    env = venv_env()
    result = subprocess.run(['bash', '-c', script], env=env, capture_output=True, text=True,
                            timeout=60, check=False)
    assert result.stdout.endswith('exit 130\n'), result.stdout + result.stderr
