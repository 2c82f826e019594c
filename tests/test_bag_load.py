"""`bag play` on a busy host delivers every message to reliable subscribers (issue 22: the
split test bag once delivered 19-83 % of a topic under three busy loops). The player's
history is deep enough for a subscriber that falls behind, and past that it waits for
acknowledgements: it falls behind the bag's clock rather than overwrite a message."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from conftest import REPO, run_cli

WBAG = REPO / 'tests' / 'data' / 'rosbag2' / 'wbag'


def test_split_bag_reaches_reliable_subscribers_completely_under_load() -> None:
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    from robot_lab.bag.read import open_bag
    from robot_lab.rclpy_session import session

    with open_bag(WBAG) as reader:
        counts = {c.topic: int(c.msgcount) for c in reader.connections}
    got = dict.fromkeys(counts, 0)
    lock = threading.Lock()

    def counter(topic: str):  # type: ignore[no-untyped-def]
        def on_msg(_msg: String) -> None:
            with lock:
                got[topic] += 1
        return on_msg

    # Keep-all: a shallow reader whose callbacks lag drops messages in its own history.
    reliable = QoSProfile(depth=10, history=HistoryPolicy.KEEP_ALL,
                          reliability=ReliabilityPolicy.RELIABLE)
    node = session().node
    subs = [node.create_subscription(String, t, counter(t), reliable) for t in counts]
    busy = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
            for _ in range(os.cpu_count() or 2)]
    try:
        played = run_cli('bag', 'play', str(WBAG), timeout=300)
        assert played.returncode == 0, played.stderr
        # The player waited for every acknowledgement before it exited: each message is in
        # a reader's history; the callbacks may still be catching up.
        deadline = time.monotonic() + 60
        while got != counts and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        for proc in busy:
            proc.kill()
            proc.wait()
        for sub in subs:
            node.destroy_subscription(sub)
    assert got == counts


def test_a_qos_override_keeps_its_depth(tmp_path: Path) -> None:
    """The deep history is the player's own choice; a depth the user asked for stays."""
    from rclpy.qos import HistoryPolicy, ReliabilityPolicy

    from robot_lab.bag.play import Player

    overrides = tmp_path / 'qos.yaml'
    overrides.write_text('AAA: {history: keep_last, depth: 5, reliability: reliable}\n')
    player = Player(WBAG, qos_overrides=overrides).open()
    try:
        depths = {t: p.qos_profile.depth for t, p in player._publishers.items()}
        assert depths['AAA'] == 5
        assert depths['BBB'] == 742  # all its messages (below 1000)
        bbb = player._publishers['BBB'].qos_profile
        assert (bbb.history, bbb.reliability) == (HistoryPolicy.KEEP_LAST,
                                                  ReliabilityPolicy.RELIABLE)
        assert player.qos['BBB'].depth == 10  # what the recorded QoS offers, as rosbag2 says
    finally:
        player.stop()
