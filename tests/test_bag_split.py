"""Split bags: `bag record --max-bag-size` / `--max-bag-duration`, info, play, reindex.

Our own split bag comes from a real publisher process recorded by `robot-lab bag record -b`;
rosbag2's own split bags (tests/data/rosbag2: the 5-file `wbag`, 6,074 messages with
stamps before the metadata's starting time, and `multiple_files` without metadata.yaml,
from rosbag2_py's reindex test) are read, played and reindexed too.
"""

from __future__ import annotations

import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import REPO, Proc, run_cli
from test_bag_recovery import PUBLISHER

import robot_lab
from robot_lab.bag.writer import BagWriter, TopicSpec
from robot_lab.errors import BagError

DATA = REPO / 'tests' / 'data' / 'rosbag2'
ROSBAG2_KEYS = ['version', 'storage_identifier', 'duration', 'starting_time', 'message_count',
                'topics_with_message_count', 'compression_format', 'compression_mode',
                'relative_file_paths', 'files', 'custom_data', 'ros_distro']
N = 400


@pytest.fixture(scope='module')
def split_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    bag = tmp_path_factory.mktemp('split') / 'burst_bag'
    env = dict(os.environ)
    recorder = Proc([str(Path(sys.executable).parent / 'robot-lab'), 'bag', 'record', '-o',
                     str(bag), '--max-bag-size', '4096', '--topics', '/burst'], env=env)
    publisher = Proc([sys.executable, '-c', PUBLISHER, str(N), '400'], env=env)
    try:
        recorder.wait_for(r"Subscribed to topic '/burst'", timeout=30)
        publisher.wait_for(r'done in', timeout=30)
    finally:
        publisher.stop()
        assert recorder.stop() == 0, recorder.output
    return bag


def _meta(bag: Path) -> dict[str, Any]:
    doc: dict[str, Any] = yaml.safe_load((bag / 'metadata.yaml').read_text())
    info: dict[str, Any] = doc['rosbag2_bagfile_information']
    return info


def test_record_max_bag_size_writes_numbered_files_listed_in_metadata(split_bag: Path) -> None:
    meta = _meta(split_bag)
    names = [f'burst_bag_{i}.mcap' for i in range(len(meta['files']))]
    assert len(names) >= 3
    assert meta['relative_file_paths'] == names == [f['path'] for f in meta['files']]
    assert sorted(p.name for p in split_bag.iterdir()) == sorted([*names, 'metadata.yaml'])
    assert sum(f['message_count'] for f in meta['files']) == meta['message_count'] == N
    assert list(meta) == ROSBAG2_KEYS
    values = robot_lab.read_topic(split_bag, '/burst')['data']
    assert values == list(range(N))
    info = run_cli('bag', 'info', str(split_bag)).stdout
    assert f'Files:             {names[0]}\n                   {names[1]}\n' in info
    assert 'Topic: /burst | Type: std_msgs/msg/Int32 | Count: 400 |' in info


def test_reindex_restores_the_metadata_of_a_split_bag(split_bag: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'burst_bag'
    shutil.copytree(split_bag, copy)
    (copy / 'metadata.yaml').unlink()
    out = run_cli('bag', 'reindex', str(copy))
    assert out.returncode == 0, out.stderr
    before, after = _meta(split_bag), _meta(copy)
    for key in ('relative_file_paths', 'files', 'message_count', 'duration', 'starting_time',
                'ros_distro'):
        assert after[key] == before[key], key
    assert [t['message_count'] for t in after['topics_with_message_count']] == [N]


def test_kill_9_mid_split_recording_then_reindex_recovers(tmp_path: Path) -> None:
    bag = tmp_path / 'killed'
    env = dict(os.environ)
    recorder = Proc([str(Path(sys.executable).parent / 'robot-lab'), 'bag', 'record', '-o',
                     str(bag), '-b', '4096', '/burst'], env=env)
    publisher = Proc([sys.executable, '-c', PUBLISHER, '5000', '500'], env=env)
    try:
        recorder.wait_for(r"Subscribed to topic '/burst'", timeout=30)
        deadline = time.monotonic() + 30
        while not (bag / 'killed_3.mcap').exists() and time.monotonic() < deadline:
            time.sleep(0.05)  # polling the folder for the 4th file (a real event)
        recorder.popen.kill()  # SIGKILL: no summary, no metadata.yaml
        recorder.popen.wait(10)
    finally:
        publisher.stop()
        recorder.stop()
    assert not (bag / 'metadata.yaml').exists()
    out = run_cli('bag', 'reindex', str(bag))
    assert out.returncode == 0, out.stderr
    meta = _meta(bag)
    assert len(meta['files']) >= 4
    assert not [p for p in bag.iterdir() if p.name.startswith('.')]
    values = robot_lab.read_topic(bag, '/burst')['data']
    assert len(values) >= 3 * 90 and values == list(range(len(values)))  # no gap, no repeat
    assert meta['message_count'] == len(values)


def test_split_by_duration_uses_message_times(tmp_path: Path) -> None:
    writer = BagWriter(tmp_path / 'timed', 'sqlite3', max_bag_duration=1)
    conn = writer.add_topic(TopicSpec('/t', 'std_msgs/msg/Int32', []))
    for i in range(35):  # 3.4 s of bag time at 10 Hz
        writer.write(conn, 1_000_000_000_000 + i * 100_000_000, bytes([0, 1, 0, 0, i, 0, 0, 0]))
    writer.close()
    meta = _meta(tmp_path / 'timed')
    assert [f['path'] for f in meta['files']] == [f'timed_{i}.db3' for i in range(4)]
    # A new file once a message is more than 1 s after the file's first one (rosbag2's rule).
    assert [f['message_count'] for f in meta['files']] == [11, 11, 11, 2]
    assert robot_lab.read_topic(tmp_path / 'timed', '/t')['data'] == list(range(35))
    with pytest.raises(BagError, match='greater than 1024'):
        BagWriter(tmp_path / 'tiny', 'mcap', max_bag_size=100)


def test_rosbag2_five_file_split_bag_plays_every_message(ros_domain: int) -> None:
    player = robot_lab.play(DATA / 'wbag')
    assert player.wait(timeout=60) and player.error is None
    assert (player.played, player.total) == (6074, 6074)
    assert sum(player.counts.values()) == 6074 and len(player.counts) == 8


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_rosbag2_reindex_test_bag(tmp_path: Path, storage: str) -> None:
    # rosbag2_py's reindex test bag; its sqlite3 files have the Foxy-era schema (no
    # type_description_hash column, QoS as integers).
    bag = tmp_path / 'multiple_files'
    shutil.copytree(DATA / f'multiple_files_{storage}', bag)
    assert run_cli('bag', 'reindex', str(bag)).returncode == 0
    meta = _meta(bag)
    suffix = 'mcap' if storage == 'mcap' else 'db3'
    assert meta['relative_file_paths'] == [f'multiple_files_{i}.{suffix}' for i in range(3)]
    assert meta['message_count'] == 3177 == sum(f['message_count'] for f in meta['files'])
    assert meta['ros_distro'] == ''  # not in these files: rosbag2's reindex leaves it empty
    assert len(robot_lab.read_topic(bag, '/chatter')) == 3177


def test_a_bag_in_another_serialization_format_is_refused_like_rosbag2() -> None:
    out = run_cli('bag', 'play', str(DATA / 'wrong_rmw_test_mcap'))
    assert out.returncode == 1
    assert 'Could not find converter for format wrong_format' in out.stderr
    assert out.stderr.count('\n') == 1  # one line, no traceback
