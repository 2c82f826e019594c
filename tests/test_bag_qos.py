"""Play offers the QoS the recorded publishers offered (rosbag2's rule), and overrides win.

A separate process publishes /scan best-effort (a sensor) and /map transient-local (a
latched map); the kit records both, then plays them back to subscribers in this process.
As with rosbag2: /map plays transient-local (a default subscriber gets every message),
/scan plays best-effort (a best-effort subscriber gets every message, a default reliable
one is incompatible and gets none, exactly as with the original publisher), and a
`--qos-profile-overrides-path` file that makes /scan reliable feeds a default subscriber.
"""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import BIN, Proc

import robot_lab
from robot_lab.bag.qos import adapt_offer, load_overrides
from robot_lab.errors import BagError
from robot_lab.rclpy_session import session

N = 20
PUBLISHER = r"""
import sys, threading, time
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from robot_lab.rclpy_session import session
node = session().node
scan = node.create_publisher(
    String, '/scan', QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
latched = node.create_publisher(
    String, '/map', QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL))
while scan.get_subscription_count() == 0 or latched.get_subscription_count() == 0:
    time.sleep(0.005)
for i in range(int(sys.argv[1])):
    scan.publish(String(data=f'scan {i}'))
    latched.publish(String(data=f'map {i}'))
    time.sleep(0.02)  # a 50 Hz sensor
print('published', flush=True)
threading.Event().wait()  # until the test stops this process
"""


class Counter:
    """A subscription in this process that collects the strings it receives.

    Its history holds all N messages (a default or sensor profile keeps 10 or 5): on a
    loaded host the test's executor can stall for longer than five 50 Hz periods, and a
    shorter history then drops the oldest messages before they are taken, whatever the QoS
    match. `reliability` is the policy under test.
    """

    def __init__(self, topic: str, reliability: Any) -> None:
        from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
        from rclpy.qos import QoSProfile
        from std_msgs.msg import String

        self.got: list[str] = []
        self.full = threading.Event()
        self._node = session().node
        self._sub = self._node.create_subscription(
            String, topic, self._take, QoSProfile(depth=N, reliability=reliability),
            callback_group=MutuallyExclusiveCallbackGroup())

    def _take(self, msg: Any) -> None:
        self.got.append(msg.data)
        if len(self.got) == N:
            self.full.set()

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)


@pytest.fixture(scope='module')
def qos_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import os

    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    bag = tmp_path_factory.mktemp('qos') / 'mixed_qos'
    rec = robot_lab.record('/scan', '/map', output=bag)
    publisher = Proc([sys.executable, '-c', PUBLISHER, str(N)], env=dict(os.environ))
    try:
        publisher.wait_for('published', timeout=30)
        deadline = time.monotonic() + 10
        while (rec.counts.get('/scan', 0) < N or rec.counts.get('/map', 0) < N) \
                and time.monotonic() < deadline:
            rec.wait(0.05)
    finally:
        rec.stop()
        publisher.stop()
    assert rec.counts == {'/scan': N, '/map': N}
    return bag


def test_recorded_offers_are_in_the_metadata(qos_bag: Path) -> None:
    meta = yaml.safe_load((qos_bag / 'metadata.yaml').read_text())
    offers = {t['topic_metadata']['name']: t['topic_metadata']['offered_qos_profiles']
              for t in meta['rosbag2_bagfile_information']['topics_with_message_count']}
    assert [(p['reliability'], p['durability']) for p in offers['/scan']] == [
        ('best_effort', 'volatile')]
    assert [(p['reliability'], p['durability']) for p in offers['/map']] == [
        ('reliable', 'transient_local')]


def test_play_offers_the_recorded_qos_to_default_and_sensor_subscribers(
        qos_bag: Path, ros_domain: int) -> None:
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy, qos_profile_sensor_data

    map_default = Counter('/map', ReliabilityPolicy.RELIABLE)
    scan_default = Counter('/scan', ReliabilityPolicy.RELIABLE)
    scan_sensor = Counter('/scan', qos_profile_sensor_data.reliability)
    try:
        player = robot_lab.play(qos_bag)  # recorded pace: 50 Hz
        offered = {t: [(i.qos_profile.reliability, i.qos_profile.durability)
                       for i in session().node.get_publishers_info_by_topic(t)]
                   for t in ('/scan', '/map')}
        assert player.wait(timeout=30) and player.error is None and player.played == 2 * N
        assert map_default.full.wait(5), map_default.got
        assert scan_sensor.full.wait(5), scan_sensor.got
    finally:
        for counter in (map_default, scan_default, scan_sensor):
            counter.close()
    assert offered == {
        '/scan': [(ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.VOLATILE)],
        '/map': [(ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)],
    }
    assert {t: q.depth for t, q in player.qos.items()} == {'/scan': 10, '/map': 10}
    assert map_default.got == [f'map {i}' for i in range(N)]
    assert scan_sensor.got == [f'scan {i}' for i in range(N)]
    assert scan_default.got == []  # reliable request vs best-effort offer: no match, as in ROS


def test_overrides_file_makes_the_best_effort_topic_reach_a_default_subscriber(
        qos_bag: Path, tmp_path: Path, ros_domain: int) -> None:
    import os

    from rclpy.qos import ReliabilityPolicy

    overrides = tmp_path / 'overrides.yaml'
    overrides.write_text('/scan:\n  history: keep_last\n  depth: 10\n'
                         '  reliability: reliable\n  durability: volatile\n')
    scan_default = Counter('/scan', ReliabilityPolicy.RELIABLE)
    try:
        player = Proc([str(BIN / 'robot-lab'), 'bag', 'play', str(qos_bag),
                       '--topics', '/scan', '--qos-profile-overrides-path', str(overrides)],
                      env=dict(os.environ))
        assert scan_default.full.wait(30), (scan_default.got, player.output)
        code = player.popen.wait(30)
        player.stop()
        assert code == 0, player.output
    finally:
        scan_default.close()
    assert scan_default.got == [f'scan {i}' for i in range(N)]
    assert 'Overriding QoS profile for topic /scan' in player.output


def test_rule_for_mixed_and_missing_offers_and_override_errors(tmp_path: Path) -> None:
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    def offer(rel: str, dur: str, deadline: int = 0) -> dict[str, Any]:
        return {'history': 'keep_last', 'depth': 5, 'reliability': rel, 'durability': dur,
                'deadline': {'sec': deadline, 'nsec': 0}, 'lifespan': {'sec': 0, 'nsec': 0},
                'liveliness': 'automatic',
                'liveliness_lease_duration': {'sec': 0, 'nsec': 0},
                'avoid_ros_namespace_conventions': False}

    warnings: list[str] = []
    same = adapt_offer('/t', [offer('best_effort', 'transient_local')] * 2, warnings.append)
    assert (same.reliability, same.durability, same.depth) == (
        ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.TRANSIENT_LOCAL, 10)
    assert not warnings
    # Any compatibility policy that differs (here only the deadline): rosbag2's default.
    mixed = adapt_offer('/t', [offer('best_effort', 'volatile', 1),
                               offer('best_effort', 'volatile', 2)], warnings.append)
    assert (mixed.reliability, mixed.durability) == (
        ReliabilityPolicy.RELIABLE, DurabilityPolicy.VOLATILE)
    assert 'Not all original publishers on topic /t offered the same QoS' in warnings[0]
    empty = adapt_offer('/t', [])
    assert (empty.reliability, empty.depth) == (ReliabilityPolicy.RELIABLE, 10)

    bad = tmp_path / 'bad.yaml'
    bad.write_text('/scan:\n  depth: 10\n  reliabilty: reliable\n')
    with pytest.raises(BagError, match=r"bad.yaml', topic '/scan': Unexpected key `reliabilty`"):
        load_overrides(bad)
    bad.write_text('/scan:\n  depth: 10\n  reliability: sometimes\n')
    with pytest.raises(BagError, match="'sometimes' is not a valid reliability"):
        load_overrides(bad)
    bad.write_text('/scan:\n  depth: 10\n  deadline: {sec: 1}\n')
    with pytest.raises(BagError, match=r'must include both seconds \(sec\) and nanoseconds'):
        load_overrides(bad)
