"""`robot-lab bag record/info/play` against the real reference nodes (issue 7 acceptance).

One 3 s recording of the running system (mcap and, in parallel, sqlite3) is made once for
the module; the nodes are stopped before playback so only the bag publishes.
"""

from __future__ import annotations

import itertools
import os
import re
import statistics
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import BIN, Proc, run_cli

from robot_lab.grading.check.base import wait_until

TOPICS = ('/sensor/temperature', '/robot/status', '/cmd_vel')
# An MCAP file's start (magic, header record with profile 'ros2'), as a killed recorder
# leaves it: no footer after it.
MCAP_HEAD = b'\x89MCAP0\r\n\x01' + (16).to_bytes(8, 'little') + \
    (4).to_bytes(4, 'little') + b'ros2' + (4).to_bytes(4, 'little') + b'test'


def _robot_lab(*args: str) -> list[str]:
    return [str(BIN / 'robot-lab'), *args]


def rosbags_messages(bag: Path, topic: str) -> list[tuple[int, Any]]:
    """(timestamp, decoded message) of one topic, read by rosbags (not by robot_lab)."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    out = []
    with Reader(bag) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, stamp, data in reader.messages(connections=conns):
            out.append((stamp, store.deserialize_cdr(data, conn.msgtype)))
    return out


def _span_ns(bag: Path) -> int:
    """The bag's span, its first message to its last, as metadata.yaml holds it."""
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    return int(meta['duration']['nanoseconds'])


def _at_rate(rate: float, count: int, bag: Path) -> bool:
    """`count` messages of a `rate` Hz topic in `bag`: about what the rate gives over the
    bag's span (its first message to its last): at least half (a starved publisher skips
    ticks), at most a second's worth more (messages taken from a reader's queue at once
    share one receive time: 87 statuses at 20 Hz in 3.98 s were seen), and at least five.
    The span is what the recorder heard, whatever part of its `--duration` discovery took
    (more on a busy host). A message recorded twice would double the count."""
    seconds = _span_ns(bag) / 1e9
    return count >= 5 and rate * seconds / 2 <= count <= rate * (seconds + 1) + 3


@pytest.fixture(scope='module')
def bags(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Path]]:
    """Record the running reference system for 3 s into an mcap bag, and into a sqlite3 bag
    from before the mcap recorder starts until it has ended.

    The sqlite3 recorder (another process) holds every message of the mcap bag's span, so
    the two can be compared for loss: it has subscribed to every topic before the other
    starts. Both with `--duration 3` side by side shared as little as 0.5 s on a busy host
    (each spends its first second or two starting and discovering)."""
    work = tmp_path_factory.mktemp('bags')
    env = dict(os.environ)
    nodes = [
        Proc(_robot_lab('run', 'robot_lab', name, '--ros-args', '-r', f'__node:={short}'),
             env=env)
        for name, short in (('sensor_node', 'sensor'), ('controller_node', 'controller'),
                            ('robot_node', 'robot'))
    ]
    recorders: list[Proc] = []
    try:
        for node, started in zip(nodes, ('Sensor node started', 'Controller node started',
                                         'Robot node started'), strict=True):
            node.wait_for(started)
        seed = Proc(_robot_lab('bag', 'record', '-s', 'sqlite3', '-o', str(work / 'seed'),
                               *TOPICS), env=env)
        recorders.append(seed)
        seed.wait_for('All requested topics are subscribed', timeout=60)
        system = Proc(_robot_lab('bag', 'record', '-o', str(work / 'system'), '--duration',
                                 '3', *TOPICS), env=env)
        recorders.append(system)
        assert system.popen.wait(30) == 0, system.output
        assert seed.stop() == 0, seed.output  # Ctrl-C ends a recording cleanly
    finally:
        for proc in recorders + nodes:
            proc.stop()
    yield {'mcap': work / 'system', 'sqlite3': work / 'seed', 'log': work}


def test_record_writes_an_mcap_bag_in_rosbag2_format(bags: dict[str, Path]) -> None:
    bag = bags['mcap']
    assert sorted(p.name for p in bag.iterdir()) == ['metadata.yaml', 'system_0.mcap']
    assert (bag / 'system_0.mcap').read_bytes()[:8] == b'\x89MCAP0\r\n'
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['version'] == 9
    assert meta['storage_identifier'] == 'mcap'
    topics = {t['topic_metadata']['name']: t['topic_metadata']
              for t in meta['topics_with_message_count']}
    assert set(topics) == set(TOPICS)
    temp = topics['/sensor/temperature']
    assert temp['type'] == 'std_msgs/msg/Float32'
    assert temp['serialization_format'] == 'cdr'
    assert re.fullmatch(r'RIHS01_[0-9a-f]{64}', temp['type_description_hash'])
    # The publisher's offered QoS, as rosbag2 Jazzy stores it (v9: names, not numbers).
    (offer,) = temp['offered_qos_profiles']
    assert offer['reliability'] == 'reliable'
    assert offer['durability'] == 'volatile'


def test_info_prints_ros2_bag_info_layout(bags: dict[str, Path]) -> None:
    result = run_cli('bag', 'info', str(bags['mcap']))
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    labels = ['Files:', 'Bag size:', 'Storage id:', 'ROS Distro:', 'Duration:', 'Start:',
              'End:', 'Messages:', 'Topic information:']
    assert [line[:19].rstrip() for line in lines[1:10]] == labels
    assert lines[1] == 'Files:             system_0.mcap'
    assert lines[3] == 'Storage id:        mcap'
    # The span from the first message to the last, as metadata.yaml holds it: the 3 s asked
    # for (checked between spins), less the part discovery took (more on a busy host).
    span = _span_ns(bags['mcap'])
    assert lines[5] == f'Duration:          {span // 10**9}.{span % 10**9:09d}s'
    assert 0 < span < 3.5e9
    assert re.fullmatch(r'Start:             \w{3} [ \d]\d \d{4} \d\d:\d\d:\d\d\.\d{9} '
                        r'\(\d+\.\d{9}\)', lines[6])
    counts = {}
    for topic, msgtype, count in re.findall(
        r'Topic: (\S+) \| Type: (\S+) \| Count: (\d+) \| Serialization Format: cdr',
        result.stdout,
    ):
        counts[topic] = int(count)
        assert msgtype == {'/sensor/temperature': 'std_msgs/msg/Float32',
                           '/robot/status': 'std_msgs/msg/String',
                           '/cmd_vel': 'geometry_msgs/msg/Twist'}[topic]
    assert _at_rate(10, counts['/sensor/temperature'], bags['mcap'])
    assert _at_rate(20, counts['/robot/status'], bags['mcap'])
    assert _at_rate(20, counts['/cmd_vel'], bags['mcap'])
    assert int(lines[8].split()[-1]) == sum(counts.values())
    assert lines[-2:] == ['Service:           0', 'Service information: ']


def test_info_of_the_single_mcap_file_matches_the_folder(bags: dict[str, Path]) -> None:
    file = bags['mcap'] / 'system_0.mcap'
    single = run_cli('bag', 'info', str(file))
    folder = run_cli('bag', 'info', str(bags['mcap']))
    assert single.returncode == 0, single.stderr
    assert f'Files:             {file}' in single.stdout
    topic_lines = [line[19:] for line in single.stdout.splitlines() if 'Topic: ' in line]
    assert topic_lines == [line[19:] for line in folder.stdout.splitlines() if 'Topic: ' in line]
    for label in ('Duration:', 'Start:', 'End:', 'Messages:', 'ROS Distro:'):
        assert [x for x in single.stdout.splitlines() if x.startswith(label)] == \
            [x for x in folder.stdout.splitlines() if x.startswith(label)]


def test_rosbags_reads_what_was_recorded(bags: dict[str, Path]) -> None:
    temps = rosbags_messages(bags['mcap'], '/sensor/temperature')
    statuses = rosbags_messages(bags['mcap'], '/robot/status')
    assert _at_rate(10, len(temps), bags['mcap'])
    assert _at_rate(20, len(statuses), bags['mcap'])
    assert all(15.0 < msg.data < 35.0 for _, msg in temps)  # 22.5 °C plus noise
    assert all(re.match(r'(OK|HIGH)\b.*°C\)$', msg.data) for _, msg in statuses), statuses[:3]
    stamps = [t for t, _ in temps]
    assert stamps == sorted(stamps)
    gaps = [(b - a) / 1e9 for a, b in itertools.pairwise(stamps)]
    assert 0.08 < statistics.median(gaps) < 0.12  # recorded at the sensor's 10 Hz
    # None lost: the sqlite3 recorder, another process, heard the same sensor from before the
    # mcap recording began until after it ended, so the mcap bag's messages are one run of
    # its messages, in order, none missing. (Matched as a run, not by value: two noisy
    # readings can be equal. A gap in time is no loss: a starved sensor skips a tick.)
    mine = [msg.data for _, msg in temps]
    theirs = [msg.data for _, msg in rosbags_messages(bags['sqlite3'], '/sensor/temperature')]
    starts = [j for j, value in enumerate(theirs) if value == mine[0]]
    assert any(theirs[j:j + len(mine)] == mine for j in starts), (mine, theirs)
    # mcap channel metadata carries what rosbag2's mcap reader looks for.
    from rosbags.rosbag2.storage_mcap import McapReader

    reader = McapReader(bags['mcap'] / 'system_0.mcap')
    reader.open()
    try:
        metas = [ch.metadata for ch in reader.channels.values()]
        schemas = {s.name: s for s in reader.schemas.values()}
    finally:
        reader.close()
    assert all(b'offered_qos_profiles' in m and b'topic_type_hash' in m for m in metas)
    assert schemas['geometry_msgs/msg/Twist'].encoding == 'ros2msg'
    assert 'Vector3 linear' in schemas['geometry_msgs/msg/Twist'].data


def test_mcap_reference_reader_validates_the_file(bags: dict[str, Path]) -> None:
    """The MCAP maintainers' reader (the spec rosbag2_storage_mcap's C++ library follows)."""
    from mcap.reader import make_reader

    with (bags['mcap'] / 'system_0.mcap').open('rb') as f:
        reader = make_reader(f, validate_crcs=True)
        assert reader.get_header().profile == 'ros2'
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes
        meta = yaml.safe_load((bags['mcap'] / 'metadata.yaml').read_text())
        assert summary.statistics.message_count == \
            meta['rosbag2_bagfile_information']['message_count']
        schemas = {s.name: s.encoding for s in summary.schemas.values()}
        assert schemas == {'std_msgs/msg/Float32': 'ros2msg', 'std_msgs/msg/String': 'ros2msg',
                           'geometry_msgs/msg/Twist': 'ros2msg'}
        for channel in summary.channels.values():
            assert channel.message_encoding == 'cdr'
            assert channel.metadata['topic_type_hash'].startswith('RIHS01_')
            assert 'reliability: reliable' in channel.metadata['offered_qos_profiles']
        stamps = [m.log_time for _, _, m in reader.iter_messages(log_time_order=True)]
        assert len(stamps) == summary.statistics.message_count
        (record,) = list(reader.iter_metadata())
        assert record.name == 'rosbag2'
        assert 'ros_distro: jazzy' in record.metadata['serialized_metadata']


class _Listener:
    """An in-process subscriber (the test's session) collecting what playback sends."""

    def __init__(self, topic: str, msgtype: Any, field: str = 'data') -> None:
        from robot_lab.rclpy_session import session

        self.values: list[Any] = []
        self.times: list[float] = []  # when the player published each (its source stamp, s)
        self.lock = threading.Lock()
        self.session = session()
        self.sub = self.session.node.create_subscription(msgtype, topic, self._on, 100)
        self.field = field

    def _on(self, msg: Any, info: Any) -> None:
        with self.lock:
            self.values.append(getattr(msg, self.field))
            self.times.append(info['source_timestamp'] * 1e-9)

    def wait_count(self, count: int, timeout: float) -> None:
        """Until `count` messages are in, or `timeout` s; the caller asserts on them."""
        wait_until(lambda: len(self.values) >= count, timeout, interval=0.02)

    def close(self) -> None:
        self.session.node.destroy_subscription(self.sub)


def _schedule_drift(recorded: list[float], published: list[float], rate: float) -> float:
    """How far (s) the player drifted from the bag's clock scaled by `rate`, from the bag's
    first quarter to its last: 0 for a player that keeps to that rate.

    A player publishes no message before its time on the scaled clock; descheduled, it
    wakes late, sends what it missed at once, then goes on on time. So the least late
    message of a quarter is on the schedule even when most are not, and the drift is the
    least lateness of the last quarter minus that of the first. Gaps between messages
    failed on loaded CI hosts (s17L5: the mean; s27B1: the median, 31 of 57 gaps inside
    bursts); a player at the wrong rate drifts by over 1 s across a 3 s bag."""
    lateness = [p - (r - recorded[0]) / rate for r, p in zip(recorded, published, strict=True)]
    quarter = max(1, len(lateness) // 4)
    return min(lateness[-quarter:]) - min(lateness[:quarter])


def _play(*args: str) -> Proc:
    proc = Proc(_robot_lab('bag', 'play', *args), env=dict(os.environ))
    try:
        assert proc.popen.wait(40) == 0, proc.output
    finally:
        proc.stop()
    return proc


def test_play_republishes_the_recorded_messages(bags: dict[str, Path]) -> None:
    from std_msgs.msg import Float32

    recorded = [msg.data for _, msg in rosbags_messages(bags['mcap'], '/sensor/temperature')]
    listener = _Listener('/sensor/temperature', Float32)
    try:
        _play(str(bags['mcap']))
        listener.wait_count(len(recorded), 3)
        assert listener.values == recorded
    finally:
        listener.close()


def test_play_start_offset_skips_the_bags_first_seconds(bags: dict[str, Path]) -> None:
    """`--start-offset 1.5` plays exactly the messages from 1.5 s into the bag on (the
    rate test covered it until it played the whole recording)."""
    from std_msgs.msg import String

    from robot_lab.bag.info import bag_info

    start = bag_info(bags['mcap']).start_ns
    recorded = [msg.data for t, msg in rosbags_messages(bags['mcap'], '/robot/status')
                if t >= start + 1_500_000_000]
    listener = _Listener('/robot/status', String)
    try:
        _play(str(bags['mcap']), '--topics', '/robot/status', '--start-offset', '1.5')
        listener.wait_count(len(recorded), 3)
        assert recorded and listener.values == recorded
    finally:
        listener.close()


def test_play_rate_two_halves_the_gaps(bags: dict[str, Path]) -> None:
    """The whole 3 s recording, ~60 messages, timed by the player's own source stamps: a
    host that does not run the player for 0.6 s (s23C2: its first 12 of 22 messages after
    `--start-offset 1.5` went out at once) leaves the schedule's lower edge in place."""
    from std_msgs.msg import String

    recorded = [t * 1e-9 for t, _ in rosbags_messages(bags['mcap'], '/robot/status')]
    expected = len(recorded)
    for rate in ('1', '2'):
        listener = _Listener('/robot/status', String)
        try:
            _play(str(bags['mcap']), '--topics', '/robot/status', '--rate', rate)
            deadline = time.monotonic() + 3
            while len(listener.times) < expected and time.monotonic() < deadline:
                time.sleep(0.02)
            times = list(listener.times)
        finally:
            listener.close()
        assert len(times) == expected
        # On its rate's schedule from the first quarter to the last. The bag lasts 3 s: at
        # --rate 2 a player that ignored the rate drifts by 1.1 s, one that inverted it by
        # 3.4 s; a correct one only if stalled for over 0.9 s through a whole quarter.
        drift = _schedule_drift(recorded, times, float(rate))
        assert abs(drift) < 0.5, (rate, drift, [round(t - times[0], 3) for t in times])


def test_the_bag_clock_starts_with_the_first_message_read(
        bags: dict[str, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    """Opening the bag and reading up to the first message are not playback time: with the
    clock started before them, every message due meanwhile went out at once."""
    import importlib

    playing = importlib.import_module('robot_lab.bag.play')  # the module, not bag.play()
    real = playing.bag_messages

    def slow_to_first(*args: Any, **kwargs: Any) -> Iterator[Any]:
        messages = real(*args, **kwargs)
        time.sleep(2.0)  # stands for a large bag's seek to a start offset
        yield from messages

    monkeypatch.setattr(playing, 'bag_messages', slow_to_first)
    player = playing.Player(bags['mcap'], topics=['/robot/status'])
    player.keep_timing = True
    player.start()
    assert player.wait(30)
    assert player.error is None
    (_, stamp0, wall0), *rest = player.published
    assert len(rest) > 30
    # A player never publishes before a message is due; early against the first message
    # means the clock ran while nothing could be published.
    early = max((stamp - stamp0) * 1e-9 - (wall - wall0) for _, stamp, wall in rest)
    assert early < 1.0, f"published up to {early:.2f} s ahead of the bag's spacing"


def test_seed_db3_single_file_info_and_play(bags: dict[str, Path]) -> None:
    """`ros2 bag info/play my_recording.db3`, as the seed runs it."""
    from std_msgs.msg import String

    db3 = bags['sqlite3'] / 'seed_0.db3'
    assert db3.is_file()
    info = run_cli('bag', 'info', str(db3))
    assert info.returncode == 0, info.stderr
    assert f'Files:             {db3}' in info.stdout
    assert 'Storage id:        sqlite3' in info.stdout
    assert 'ROS Distro:        jazzy' in info.stdout
    match = re.search(r'Topic: /robot/status \| Type: std_msgs/msg/String \| Count: (\d+)',
                      info.stdout)
    # recorded from before the 3 s mcap recording until after it
    assert match and _at_rate(20, int(match.group(1)), bags['sqlite3'])
    recorded = [msg.data for _, msg in rosbags_messages(db3, '/robot/status')]
    assert len(recorded) == int(match.group(1))
    listener = _Listener('/robot/status', String)
    try:
        _play(str(db3), '--topics', '/robot/status', '--rate', '4')
        listener.wait_count(len(recorded), 3)
        assert listener.values == recorded
    finally:
        listener.close()


def test_existing_output_folder_is_refused(tmp_path: Path) -> None:
    (tmp_path / 'taken').mkdir()
    result = run_cli('bag', 'record', '-o', str(tmp_path / 'taken'), '/sensor/temperature')
    assert result.returncode == 1
    line = result.stderr.strip()
    assert f"Output folder '{tmp_path / 'taken'}' already exists." in line
    assert 'fix:' in line and len(line.splitlines()) == 1


def test_unknown_topic_is_waited_for_and_reported(tmp_path: Path) -> None:
    bag = tmp_path / 'waiting'
    result = run_cli('bag', 'record', '-o', str(bag), '--duration', '2.5', '/no/such/topic')
    assert result.returncode == 0, result.stderr
    assert "Topic '/no/such/topic' not found... waiting" in result.stderr
    info = run_cli('bag', 'info', str(bag))
    assert 'Messages:          0' in info.stdout


@pytest.mark.parametrize(('name', 'content', 'expected'), [
    ('notes.txt', b'hello', 'is not a rosbag2 file'),
    ('broken.mcap', b'not an mcap file at all', 'is not an MCAP file'),
    ('cut.mcap', MCAP_HEAD + bytes(100), 'is incomplete'),
    ('junk.db3', b'SQLite format 2 junk' * 10, 'not a rosbag2 sqlite3 database'),
    ('missing', None, 'does not exist'),
    ('empty_dir', 'dir', 'is not a rosbag2 bag'),
])
def test_unreadable_or_foreign_bags_are_explained(
    tmp_path: Path, name: str, content: bytes | str | None, expected: str
) -> None:
    path = tmp_path / name
    if content == 'dir':
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    for verb in ('info', 'play'):
        result = run_cli('bag', verb, str(path))
        assert result.returncode == 1, result.stdout
        line = result.stderr.strip()
        assert expected in line and 'fix:' in line and len(line.splitlines()) == 1, line


def test_unknown_message_type_in_a_bag(tmp_path: Path) -> None:
    """A bag holding a type this environment cannot load: play skips it, read says why."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    import robot_lab

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg('float64 level', 'tank_msgs/msg/Level'))
    bag = tmp_path / 'foreign_types'
    level = store.types['tank_msgs/msg/Level'](level=0.5)
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection('/tank/level', 'tank_msgs/msg/Level', typestore=store)
        writer.write(conn, 1_000_000_000, store.serialize_cdr(level, 'tank_msgs/msg/Level'))
    info = run_cli('bag', 'info', str(bag))
    assert 'Type: tank_msgs/msg/Level | Count: 1' in info.stdout
    with pytest.raises(robot_lab.BagError, match="'tank_msgs/msg/Level', which is not known"):
        robot_lab.read_topic(bag, '/tank/level', fields=('level',))
    played = run_cli('bag', 'play', str(bag))
    assert played.returncode == 0
    assert "Ignoring a topic '/tank/level', reason:" in played.stderr
