"""Bags the kit did not write: a metadata.yaml whose offered QoS text differs from the
storage's, as in rosbag2's own talker test bags (deadline 0 in metadata.yaml, infinite in
the .mcap/.db3). rosbags' reader matched topics by that text too and yielded 0 of 20
messages; rosbag2 (and now the kit) match by topic name and type."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

import robot_lab
from robot_lab.bag.read import bag_messages, open_bag
from robot_lab.errors import BagError
from robot_lab.rclpy_session import session

INFINITE = {'sec': 2147483647, 'nsec': 4294967295}


def _write_bag(path: Path, storage: str, count: int) -> None:
    """`count` std_msgs/String on /topic, then metadata.yaml's deadline set to 0 the way
    rosbag2's talker bags have it (the storage keeps the infinite one)."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    forever = QosTime(**INFINITE)
    offer = Qos(QosHistory.UNKNOWN, 0, QosReliability.RELIABLE, QosDurability.VOLATILE,
                forever, forever, QosLiveliness.AUTOMATIC, forever, False)
    plugin = StoragePlugin.MCAP if storage == 'mcap' else StoragePlugin.SQLITE3
    string = store.types['std_msgs/msg/String']
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        conn = writer.add_connection('/topic', 'std_msgs/msg/String', typestore=store,
                                     offered_qos_profiles=[offer])
        for i in range(count):
            data = store.serialize_cdr(string(data=f'Hello, world! {i}'), 'std_msgs/msg/String')
            writer.write(conn, 1_585_866_235_000_000_000 + i * 100_000_000, data)
    metadata = path / 'metadata.yaml'
    text = metadata.read_text()
    deadline = '        deadline:\n          nsec: 4294967295\n          sec: 2147483647\n'
    assert deadline in text
    metadata.write_text(text.replace(deadline,
                                     '        deadline:\n          nsec: 0\n          sec: 0\n'))


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_bag_whose_metadata_qos_differs_is_read_and_played(
        tmp_path: Path, storage: str, ros_domain: int) -> None:
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
    from std_msgs.msg import String

    bag = tmp_path / f'talker_{storage}'
    _write_bag(bag, storage, 10)
    with open_bag(bag) as reader:
        assert sum(1 for _ in reader.messages()) == 0  # rosbags' own matching: nothing
        assert [bytes(d)[8:-1].decode() for _, _, d in bag_messages(reader, reader.connections)
                ][-1] == 'Hello, world! 9'
    assert robot_lab.read_topic(bag, '/topic', ['data'])['data'] == [
        f'Hello, world! {i}' for i in range(10)]

    # Played to a default (reliable, volatile, depth 10) subscriber: every message arrives.
    sess = session()
    got: list[str] = []
    all_in = threading.Event()

    def take(msg: String) -> None:
        got.append(msg.data)
        if len(got) == 10:
            all_in.set()

    sub = sess.node.create_subscription(String, '/topic', take, 10,
                                        callback_group=MutuallyExclusiveCallbackGroup())
    try:
        player = robot_lab.play(bag, rate=5.0)
        assert player.wait(timeout=30)
        assert all_in.wait(5), got
    finally:
        sess.node.destroy_subscription(sub)
    assert player.error is None and player.played == 10
    assert got == [f'Hello, world! {i}' for i in range(10)]


def test_play_delay_waits_before_the_first_message(tmp_path: Path, ros_domain: int) -> None:
    bag = tmp_path / 'delayed'
    _write_bag(bag, 'mcap', 2)
    # Timed from the call: the player's thread starts its delay before play() returns,
    # and under load play() itself took 0.09 s (CI measured 0.91 s from its return).
    started = time.monotonic()
    player = robot_lab.play(bag, delay=1.0)
    first = None
    while first is None and time.monotonic() - started < 10:
        if player.played:
            first = time.monotonic() - started
        time.sleep(0.01)
    assert player.wait(timeout=10) and player.played == 2
    assert first is not None and first >= 1.0  # rosbag2's --delay: sleep, then play
    with pytest.raises(BagError, match='less than zero'):
        robot_lab.play(bag, delay=-1)
