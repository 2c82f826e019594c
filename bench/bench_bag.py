"""ROS bag numbers (issue 7): loss-free recording rate and playback timing error.

- Recording: a separate publisher process sends N numbered std_msgs/Int32 reliably at
  R Hz (2 s) to `robot-lab bag record` (its own process); the bag is read back with
  rosbags and checked for gaps. Reported per rate: messages lost (median over runs),
  the rate the publisher actually achieved, and the highest rate with no loss in any run.
- Playback: a 100 Hz stream is recorded, then `robot-lab bag play` (cold process) sends
  it to a subscriber in this process; error = median |replayed gap - recorded gap / rate|
  over all consecutive messages, for --rate 1 and 2 (median over runs).

- Reindex: seconds to rebuild metadata.yaml of a 200,000-message .mcap file, complete
  (read from its summary) and with its last 10 % cut off (streamed and rewritten).

    .venv/bin/python bench/bench_bag.py [--runs 3] [--rates 1000 2000 5000 10000]

Uses ROS_DOMAIN_ID 79 unless set (keep benchmarks off other people's domains).
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from busy import busy_loops

os.environ.setdefault('ROS_DOMAIN_ID', '79')

from robot_lab.env import ros_environment  # after the domain is chosen
from robot_lab.process import spawn, stop

BIN = Path(sys.executable).parent
CLI = str(BIN / 'robot-lab')

PUBLISHER = r"""
import sys, time
from rclpy.duration import Duration
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Int32
from robot_lab.rclpy_session import session
count, rate = int(sys.argv[1]), float(sys.argv[2])
node = session().node
reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
pub = node.create_publisher(Int32, '/bench', reliable)
while pub.get_subscription_count() == 0:
    time.sleep(0.005)
start = time.monotonic()
for i in range(count):
    while time.monotonic() < start + i / rate:
        pass
    pub.publish(Int32(data=i))
took = time.monotonic() - start
pub.wait_for_all_acked(Duration(seconds=10))
print(f'achieved {count / took:.1f}', flush=True)
"""


def _wait_line(proc: object, prefix: str, timeout: float) -> str:
    out = proc.stdout  # type: ignore[attr-defined]
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = out.readline().decode()
        if not line:
            break
        if line.startswith(prefix) or prefix in line:
            return line
    raise RuntimeError(f'no {prefix!r} within {timeout} s')


def _bag_numbers(bag: Path) -> list[int]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(bag) as reader:
        return [store.deserialize_cdr(d, c.msgtype).data for c, _, d in reader.messages()]


def record_once(work: Path, rate: float, seconds: float = 2.0) -> tuple[int, float, Path]:
    """(messages lost, publisher's achieved rate, bag) for one recording at `rate` Hz."""
    count = int(rate * seconds)
    bag = work / f'rec_{int(rate)}_{time.monotonic_ns()}'
    env = ros_environment()
    recorder = spawn([CLI, 'bag', 'record', '-o', str(bag), '/bench'], env=env)
    try:
        publisher = spawn([sys.executable, '-c', PUBLISHER, str(count), str(rate)], env=env,
                          stderr=None)
        try:
            achieved = float(_wait_line(publisher, 'achieved', 60).split()[1])
            publisher.wait(10)
        finally:
            stop(publisher)
    finally:
        stop(recorder)
    numbers = _bag_numbers(bag)
    lost = count - len(set(numbers))
    if numbers != sorted(numbers):
        lost = max(lost, 1)
    return lost, achieved, bag


def playback_error(bag: Path, rate: float) -> float:
    """Median |replayed gap - recorded gap / rate| in ms, seen by a subscriber here."""
    from std_msgs.msg import Int32

    from robot_lab.bag.read import open_bag
    from robot_lab.rclpy_session import session

    with open_bag(bag) as reader:
        stamps = [t for _, t, _ in reader.messages()]
    received: list[float] = []
    lock = threading.Lock()

    def on_msg(_msg: Int32) -> None:
        with lock:
            received.append(time.monotonic())

    node = session().node
    sub = node.create_subscription(Int32, '/bench', on_msg, 1000)
    try:
        player = spawn([CLI, 'bag', 'play', str(bag), '--rate', str(rate)],
                       env=ros_environment())
        player.wait(120)
        deadline = time.monotonic() + 5
        while len(received) < len(stamps) and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        node.destroy_subscription(sub)
    if len(received) != len(stamps):
        raise RuntimeError(f'replay delivered {len(received)} of {len(stamps)} messages')
    recorded = [(b - a) / 1e9 / rate for a, b in itertools.pairwise(stamps)]
    replayed = [b - a for a, b in itertools.pairwise(received)]
    return 1000 * statistics.median(abs(x - y) for x, y in zip(recorded, replayed, strict=True))


def publish_side_error(bag: Path, rate: float) -> float:
    """The player's own timing (robot_lab.play in this process): median gap error in ms."""
    from robot_lab.bag.play import Player
    from robot_lab.bag.read import open_bag

    with open_bag(bag) as reader:
        stamps = [t for _, t, _ in reader.messages()]
    player = Player(bag, rate=rate)
    player.keep_timing = True  # before start(): every publish time is kept
    player.start()
    player.wait(120)
    sent = [wall for _, _, wall in player.published]
    recorded = [(b - a) / 1e9 / rate for a, b in itertools.pairwise(stamps)]
    replayed = [b - a for a, b in itertools.pairwise(sent)]
    return 1000 * statistics.median(abs(x - y) for x, y in zip(recorded, replayed, strict=True))


WBAG = Path(__file__).resolve().parent.parent / 'tests' / 'data' / 'rosbag2' / 'wbag'


def delivery_under_load(work: Path, busy: int, shallow: bool,
                        timeout: float = 300.0) -> tuple[float, float, float]:
    """rosbag2's split test bag (8 topics, 6,074 messages) played by `robot-lab bag play`
    (cold process) to reliable keep-all subscribers here, `busy` loops beside it:
    (share of messages delivered, worst topic's share, s the last one came after the bag's
    own span). `shallow`: the recorded depth 10 kept (a QoS override file), so the player
    waits for acknowledgements every 10 messages instead of using its deep history;
    stopped after `timeout` s."""
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    from robot_lab.bag.read import open_bag
    from robot_lab.rclpy_session import session

    with open_bag(WBAG) as reader:
        counts = {c.topic: int(c.msgcount) for c in reader.connections}
        span = (int(reader.end_time) - int(reader.start_time)) / 1e9
    got = dict.fromkeys(counts, 0)
    times: list[float] = []
    lock = threading.Lock()

    def counter(topic: str) -> object:
        def on_msg(_msg: String) -> None:
            with lock:
                got[topic] += 1
                times.append(time.monotonic())
        return on_msg

    # KEEP_ALL: a depth-10 reader whose callbacks lag drops messages in its own history,
    # acknowledged or not, whatever the player does (measured: 27 % delivered).
    reliable = QoSProfile(depth=10, history=HistoryPolicy.KEEP_ALL,
                          reliability=ReliabilityPolicy.RELIABLE)
    node = session().node
    subs = [node.create_subscription(String, t, counter(t), reliable) for t in counts]
    cmd = [CLI, 'bag', 'play', str(WBAG)]
    if shallow:
        overrides = work / 'shallow.yaml'
        overrides.write_text(''.join(
            f'{t}: {{history: keep_last, depth: 10, reliability: reliable}}\n'
            for t in counts))
        cmd += ['--qos-profile-overrides-path', str(overrides)]
    try:
        with busy_loops(busy):
            player = spawn(cmd, env=ros_environment())
            try:
                player.wait(timeout)
            except subprocess.TimeoutExpired:
                stop(player)
            total = sum(counts.values())
            seen, still = -1, time.monotonic()
            while sum(got.values()) < total and time.monotonic() - still < 3.0:
                time.sleep(0.05)  # polling the counts until complete or 3 s without news
                if sum(got.values()) != seen:
                    seen, still = sum(got.values()), time.monotonic()
    finally:
        for sub in subs:
            node.destroy_subscription(sub)
    worst = min(got[t] / n for t, n in counts.items())
    lag = (max(times) - min(times) - span) if times else float('nan')
    return sum(got.values()) / sum(counts.values()), worst, lag


def reindex_times(work: Path, count: int) -> tuple[float, float, int]:
    """Seconds to reindex a `count`-message .mcap bag whose metadata.yaml is gone, when the
    file is complete and when its last 10 % were cut off (a killed recorder); messages kept."""
    import shutil

    from robot_lab.bag import reindex as reindex_fn  # the function (the module shares its name)
    from robot_lab.bag.writer import BagWriter, TopicSpec

    bag = work / 'reindex_bench'
    shutil.rmtree(bag, ignore_errors=True)
    writer = BagWriter(bag, 'mcap')
    conn = writer.add_topic(TopicSpec('/t', 'std_msgs/msg/Int32', []))
    for i in range(count):
        writer.write(conn, 10**18 + i * 1000, bytes([0, 1, 0, 0]) + i.to_bytes(4, 'little'))
        if i % 5000 == 0:
            writer.flush()
    writer.close()
    (bag / 'metadata.yaml').unlink()
    start = time.perf_counter()
    reindex_fn(bag)
    complete = time.perf_counter() - start
    (bag / 'metadata.yaml').unlink()
    file = bag / 'reindex_bench_0.mcap'
    data = file.read_bytes()
    file.write_bytes(data[: len(data) * 9 // 10])
    start = time.perf_counter()
    report = reindex_fn(bag)
    return complete, time.perf_counter() - start, report.message_count


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--rates', type=float, nargs='+', default=[1000, 2000, 5000, 10000])
    parser.add_argument('--busy', type=int, default=3, help='busy loops during bag play delivery')
    parser.add_argument('--only-delivery', action='store_true',
                        help='measure only bag play delivery under load')
    parser.add_argument('--reindex-messages', type=int, default=200_000,
                        help='size of the bag for the reindex timing (0: skip it)')
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix='bench_bag_') as tmp:
        work = Path(tmp)
        print(f'# bag play delivery: rosbag2 split test bag (8 topics, 6,074 messages) to '
              f'reliable keep-all subscribers, {args.busy} busy loops, {args.runs} runs')
        for shallow in (False, True):
            runs = [delivery_under_load(work, args.busy, shallow, 60.0 if shallow else 300.0)
                    for _ in range(1 if shallow else args.runs)]
            how = ('depth 10, waiting for acknowledgements every 10 (stopped after 60 s)'
                   if shallow else 'deep publisher history (default, <= 1000)')
            print(f'{how}: delivered {100 * statistics.median(r[0] for r in runs):.1f} % '
                  f'(worst topic in any run {100 * min(r[1] for r in runs):.1f} %), '
                  f'last message {statistics.median(r[2] for r in runs):.2f} s after the '
                  "bag's span (median)")
        if args.only_delivery:
            return 0
        print(f'# bag record: reliable Int32 for 2 s, {args.runs} runs per rate '
              f'(ROS_DOMAIN_ID={os.environ["ROS_DOMAIN_ID"]})')
        print(f'{"rate Hz":>8} {"lost (median)":>14} {"lost (max)":>11} {"achieved Hz":>12}')
        best = 0.0
        for rate in args.rates:
            results = [record_once(work, rate)[:2] for _ in range(args.runs)]
            lost = [r[0] for r in results]
            achieved = statistics.median(r[1] for r in results)
            print(f'{rate:8.0f} {statistics.median(lost):14.0f} {max(lost):11d} '
                  f'{achieved:12.1f}')
            if max(lost) == 0:
                best = max(best, rate)
        print(f'highest rate recorded with no loss in any run: {best:.0f} Hz')

        print(f'# bag play timing: 100 Hz stream, 3 s, {args.runs} runs; median |Δt| between '
              'recorded gap / rate and replayed gap')
        bags = [record_once(work, 100.0, seconds=3.0)[2] for _ in range(args.runs)]
        for rate in (1.0, 2.0):
            end_to_end = [playback_error(bag, rate) for bag in bags]
            sender = [publish_side_error(bag, rate) for bag in bags]
            print(f'--rate {rate:g}: at a subscriber (CLI player) '
                  f'{statistics.median(end_to_end):.3f} ms '
                  f'(runs: {", ".join(f"{e:.3f}" for e in end_to_end)}); '
                  f'at the publisher {statistics.median(sender):.3f} ms '
                  f'(runs: {", ".join(f"{e:.3f}" for e in sender)})')
        if args.reindex_messages:
            runs = [reindex_times(work, args.reindex_messages) for _ in range(args.runs)]
            print(f'# bag reindex of one {args.reindex_messages}-message .mcap '
                  f'(metadata.yaml deleted), median of {args.runs} runs')
            print(f'complete file: {statistics.median(r[0] for r in runs):.2f} s; '
                  f'last 10 % cut off: {statistics.median(r[1] for r in runs):.2f} s, '
                  f'{statistics.median(r[2] for r in runs):.0f} messages recovered')
        print(f'load average during the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores')
    return 0


if __name__ == '__main__':
    sys.exit(main())
