"""robot_lab.record / play / bag_info / read_topic and the notebook widgets, in-process.

The recordings are of the real reference nodes; playback is checked by a subscriber in
this process, against what rosbags (not robot_lab) reads from the same bag.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import BIN, Proc

import robot_lab


def _until(condition: Callable[[], bool], timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f'timed out waiting for {what}')
        time.sleep(0.02)


def _rosbags(bag: Path, topic: str) -> list[Any]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(bag) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        return [store.deserialize_cdr(d, c.msgtype) for c, _, d in reader.messages(conns)]


def _node(name: str, short: str) -> Proc:
    return Proc([str(BIN / 'robot-lab'), 'run', 'robot_lab', name, '--ros-args', '-r',
                 f'__node:={short}'], env=dict(os.environ))


@pytest.fixture(scope='module')
def system_bag(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """2 s of the sensor and controller, recorded with robot_lab.record(duration=2)."""
    bag = tmp_path_factory.mktemp('api') / 'system'
    nodes = [_node('sensor_node', 'sensor'), _node('controller_node', 'controller')]
    try:
        nodes[0].wait_for('Sensor node started')
        nodes[1].wait_for('Controller node started')
        rec = robot_lab.record('/sensor/temperature', '/cmd_vel', output=bag, duration=2.0)
        assert rec.wait(15), rec.log_lines
        rec.stop()
    finally:
        for node in nodes:
            node.stop()
    yield bag


def test_record_context_manager_counts_live_and_keeps_every_message(
    start, tmp_path: Path
) -> None:
    start('robot-lab', 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
          '-p', 'sensor_rate:=50').wait_for('Sensor node started')
    bag = tmp_path / 'ctx'
    with robot_lab.record('/sensor/temperature', output=bag) as rec:
        _until(lambda: rec.counts.get('/sensor/temperature', 0) >= 20, 10, 'live counts')
        assert rec.running and rec.elapsed > 0
    assert rec.finished
    info = robot_lab.bag_info(bag)
    # stop() drains what DDS already delivered: the bag has everything counted.
    assert info.topic('/sensor/temperature').count == rec.counts['/sensor/temperature'] >= 20
    assert info.storage_id == 'mcap' and info.version == 9
    assert any("Subscribed to topic '/sensor/temperature'" in line for line in rec.log_lines)


def test_kernel_interrupt_during_recording_closes_the_bag(start, tmp_path: Path) -> None:
    start('robot-lab', 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
          '-p', 'sensor_rate:=50').wait_for('Sensor node started')
    bag = tmp_path / 'interrupted'
    with pytest.raises(KeyboardInterrupt), robot_lab.record('/sensor/temperature',
                                                            output=bag) as rec:
        _until(lambda: rec.counts.get('/sensor/temperature', 0) >= 10, 10, 'messages')
        raise KeyboardInterrupt  # what the kernel raises on "Interrupt"
    values = _rosbags(bag, '/sensor/temperature')
    assert len(values) == rec.counts['/sensor/temperature'] >= 10
    assert (bag / 'metadata.yaml').is_file()


def test_record_handle_with_duration_and_sqlite(start, tmp_path: Path) -> None:
    start('robot-lab', 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r',
          '__node:=sensor').wait_for('Sensor node started')
    rec = robot_lab.record('/sensor/temperature', output=tmp_path / 'timed', duration=1.5,
                           storage='sqlite3')
    assert rec.wait(15)
    assert rec.stop() == tmp_path / 'timed'
    assert 1.5 <= rec.elapsed < 5.0
    info = robot_lab.bag_info(tmp_path / 'timed')
    assert info.storage_id == 'sqlite3' and info.files == ['timed_0.db3']
    assert info.message_count == rec.total >= 8  # 10 Hz for 1.5 s, after discovery


def test_max_messages_stops_the_recording_at_exactly_n(start, tmp_path: Path) -> None:
    start('robot-lab', 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
          '-p', 'sensor_rate:=50').wait_for('Sensor node started')
    rec = robot_lab.record('/sensor/temperature', output=tmp_path / 'n', max_messages=15)
    assert rec.wait(15)
    rec.stop()
    assert len(_rosbags(tmp_path / 'n', '/sensor/temperature')) == 15


def test_existing_folder_and_missing_topics_are_errors(tmp_path: Path) -> None:
    (tmp_path / 'old').mkdir()
    with pytest.raises(robot_lab.BagError, match=r"Output folder '.*old' already exists"):
        robot_lab.record('/x', output=tmp_path / 'old')
    with pytest.raises(robot_lab.BagError, match='at least one option'):
        robot_lab.record(output=tmp_path / 'none')


def test_read_topic_gives_columns_for_plots(system_bag: Path) -> None:
    temps = robot_lab.read_topic(system_bag, '/sensor/temperature')
    expected = [m.data for m in _rosbags(system_bag, '/sensor/temperature')]
    assert 10 <= len(temps) <= 22  # 10 Hz for 2 s, less discovery time (at most 1 s)
    assert temps['data'] == pytest.approx(expected)
    assert temps.t[0] >= 0 and temps.t == sorted(temps.t) and temps.t[-1] < 2.5
    cmd = robot_lab.read_topic(system_bag, 'cmd_vel', fields=('linear.x', 'angular/z'))
    twists = _rosbags(system_bag, '/cmd_vel')
    assert cmd['linear.x'] == [m.linear.x for m in twists]
    assert cmd['angular/z'] == [m.angular.z for m in twists]
    with pytest.raises(robot_lab.BagError, match=r"'/nope' is not in bag .*/cmd_vel"):
        robot_lab.read_topic(system_bag, '/nope')
    with pytest.raises(robot_lab.BagError, match="'speed' in field path"):
        robot_lab.read_topic(system_bag, '/cmd_vel', fields='linear.speed')


def test_play_handle_pause_resume_progress(system_bag: Path) -> None:
    from std_msgs.msg import Float32

    from robot_lab.rclpy_session import session

    recorded = [m.data for m in _rosbags(system_bag, '/sensor/temperature')]
    got: list[float] = []
    node = session().node
    sub = node.create_subscription(Float32, '/sensor/temperature',
                                   lambda m: got.append(m.data), 100)
    try:
        p = robot_lab.play(system_bag, topics=['/sensor/temperature'])
        _until(lambda: p.played >= 5, 10, 'first messages')
        p.pause()
        at_pause, progress = p.played, p.progress
        assert 0.0 < progress < 1.0
        time.sleep(0.4)  # a paused player must stay silent for this window (4 periods)
        assert p.played == at_pause and p.paused
        p.resume()
        assert p.wait(10)
        assert p.progress == 1.0 and p.played == p.total == len(recorded)
        _until(lambda: len(got) >= len(recorded), 3, 'delivery')
        assert got == recorded
        assert 'Pausing play.' in '\n'.join(p.log_lines)
    finally:
        node.destroy_subscription(sub)


def test_widgets_record_and_play_headless(system_bag: Path, start, tmp_path: Path,
                                          capfd: pytest.CaptureFixture[str]) -> None:
    start('robot-lab', 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
          '-p', 'sensor_rate:=50').wait_for('Sensor node started')
    rec = robot_lab.recorder('/sensor/temperature', output=tmp_path / 'w')
    assert rec.widget is not None  # the ipywidgets tree builds
    rec.start()
    _until(lambda: rec.counts.get('/sensor/temperature', 0) >= 5, 10, 'widget counts')
    assert rec.running and rec._stop_button.disabled is False
    assert '/sensor/temperature' in rec.status_html()
    path = rec.stop()
    assert path == tmp_path / 'w' and (path / 'metadata.yaml').is_file()
    assert "Subscribed to topic '/sensor/temperature'" in rec.log.text
    assert rec._start_button.disabled is False

    pw = robot_lab.player(system_bag, rate=4.0)
    assert pw.widget is not None
    pw.play()
    assert pw.wait(10)
    pw.refresh()
    assert pw.progress == 1.0 and pw._progress.value == 1.0
    assert 'finished' in pw.status_text()
    out = capfd.readouterr()
    # Background threads wrote into the widgets' logs, not into the cell's output.
    assert 'rosbag2_recorder' not in out.out and 'rosbag2_player' not in out.out
