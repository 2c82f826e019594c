"""tf2 numbers (issue 49): lookups through a chain, and a listener taking 1 kHz of /tf.

- Lookup: `lookup_transform_core` from the end of a chain of N dynamic frames (10 and 100),
  each with 10 s of samples at 100 Hz, at time 0 (latest common time) and at a time between
  samples (lerp + slerp on every link); microseconds per lookup, median of the runs.
- Insert: `set_transform` of one sample into a 10 s cache already full at 1 kHz.
- Listener: a publisher process sends /tf (one TFMessage, 2 transforms: odom->base_link and
  base_link->laser, stamped now) at 1 kHz for 5 s; a TransformListener in this process on the
  kit's session (as in a notebook kernel) takes it. Reported: messages received of those
  sent, the lag of the newest transform in the buffer when the stream ends (how far behind
  the listener is), and this process's CPU over the stream (percent of one core).

    .venv/bin/python bench/bench_tf2.py [--runs 3] [--seconds 5] [--rate 1000]

Run it in its own network namespace (see helper_brief: unshare --net --mount).
Uses ROS_DOMAIN_ID 81 unless set.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from typing import Any

os.environ.setdefault('ROS_DOMAIN_ID', '81')

from robot_lab.env import ros_environment  # after the domain is chosen
from robot_lab.process import spawn, stop

PUBLISHER = r"""
import sys, time
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from robot_lab.rclpy_session import session
seconds, rate = float(sys.argv[1]), float(sys.argv[2])
node = session().node
pub = node.create_publisher(TFMessage, '/tf', 100)
while pub.get_subscription_count() == 0:
    time.sleep(0.005)
time.sleep(0.5)
def tf(parent, child, x):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    return t
a, b = tf('odom', 'base_link', 0.0), tf('base_link', 'laser', 0.2)
clock = node.get_clock()
count = int(seconds * rate)
start = time.monotonic()
for i in range(count):
    while time.monotonic() < start + i / rate:
        pass
    now = clock.now().to_msg()
    a.header.stamp = now
    b.header.stamp = now
    a.transform.translation.x = i * 0.001
    pub.publish(TFMessage(transforms=[a, b]))
took = time.monotonic() - start
print(f'sent {count} {count / took:.1f}', flush=True)
time.sleep(1.0)
"""


def _tf(parent: str, child: str, stamp_ns: int, x: float, yaw: float) -> Any:
    from geometry_msgs.msg import TransformStamped

    from robot_lab.tf2.linear_math import quaternion_from_euler

    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp.sec, t.header.stamp.nanosec = divmod(stamp_ns, 10**9)
    t.transform.translation.x = x
    q = quaternion_from_euler(0.0, 0.0, yaw)
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = q
    return t


def lookup_us(frames: int, at_zero: bool, lookups: int = 2000) -> float:
    """Microseconds per lookup from the end of a `frames`-long chain."""
    from rclpy.time import Time

    from robot_lab.tf2.buffer_core import BufferCore

    core = BufferCore()
    base = 1_000 * 10**9
    for k in range(1000):  # 10 s at 100 Hz
        stamp = base + k * 10**7
        for i in range(frames):
            core.set_transform(_tf(f'f{i}', f'f{i + 1}', stamp, 0.1, 0.001 * k), 'bench')
    when = Time() if at_zero else Time(nanoseconds=base + 500 * 10**7 + 3 * 10**6)
    target, source = 'f0', f'f{frames}'
    started = time.perf_counter()
    for _ in range(lookups):
        core.lookup_transform_core(target, source, when)
    return (time.perf_counter() - started) / lookups * 1e6


def insert_us(samples: int = 5000) -> float:
    from robot_lab.tf2.buffer_core import BufferCore

    core = BufferCore()
    base = 1_000 * 10**9
    for k in range(10_000):
        core.set_transform(_tf('odom', 'base_link', base + k * 10**6, 0.0, 0.0), 'bench')
    msgs = [_tf('odom', 'base_link', base + (10_000 + k) * 10**6, 0.0, 0.0)
            for k in range(samples)]
    started = time.perf_counter()
    for msg in msgs:
        core.set_transform(msg, 'bench')
    return (time.perf_counter() - started) / samples * 1e6


def listener_run(seconds: float, rate: float) -> tuple[int, int, float, float]:
    """(received, sent, lag of the newest sample at the end in ms, CPU % of one core)."""
    import rclpy
    from rclpy.time import Time
    from tf2_msgs.msg import TFMessage

    from robot_lab.rclpy_session import session
    from robot_lab.tf2.buffer import Buffer
    from robot_lab.tf2.listener import TransformListener

    sess = session()
    node = rclpy.create_node(f'bench_tf2_listener_{os.getpid()}', context=sess.context)
    buffer = Buffer(node=node)
    received = [0]

    class Counting(TransformListener):
        def callback(self, data: TFMessage) -> None:
            received[0] += 1
            super().callback(data)

    listener = Counting(buffer, node)
    sess.add_node(node)
    publisher = spawn([sys.executable, '-c', PUBLISHER, str(seconds), str(rate)],
                      env=ros_environment())
    try:
        cpu0, wall0 = time.process_time(), time.monotonic()
        out = publisher.stdout
        assert out is not None
        line = ''
        while not line.startswith('sent'):
            line = out.readline().decode()
            if not line:
                raise RuntimeError('the publisher ended without a report')
        cpu1, wall1 = time.process_time(), time.monotonic()
        newest = buffer.lookup_transform_core('odom', 'laser', Time()).header.stamp
        lag_ms = (node.get_clock().now().nanoseconds
                  - (newest.sec * 10**9 + newest.nanosec)) / 1e6
        deadline = time.monotonic() + 2.0
        sent = int(line.split()[1])
        while received[0] < sent and time.monotonic() < deadline:
            time.sleep(0.01)
        publisher.wait(10)
    finally:
        stop(publisher)
        listener.unregister()
        sess.remove_node(node)
        node.destroy_node()
    return received[0], sent, lag_ms, 100 * (cpu1 - cpu0) / (wall1 - wall0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--seconds', type=float, default=5.0)
    parser.add_argument('--rate', type=float, default=1000.0)
    args = parser.parse_args()
    for frames in (10, 100):
        for at_zero in (True, False):
            runs = [lookup_us(frames, at_zero, 2000 if frames == 10 else 300)
                    for _ in range(args.runs)]
            print(f'lookup through {frames:3d} frames at '
                  f'{"time 0       " if at_zero else "between samples"}: '
                  f'{statistics.median(runs):8.1f} us', flush=True)
    print(f'set_transform into a full 10 s cache: '
          f'{statistics.median(insert_us() for _ in range(args.runs)):.1f} us', flush=True)
    results = [listener_run(args.seconds, args.rate) for _ in range(args.runs)]
    got = [r[0] / r[1] for r in results]
    print(f'listener at {args.rate:.0f} Hz for {args.seconds:.0f} s: received '
          f'{statistics.median(got) * 100:.1f} % of sent (min {min(got) * 100:.1f} %), lag of '
          f'the newest transform at the end {statistics.median(r[2] for r in results):.1f} ms, '
          f'CPU {statistics.median(r[3] for r in results):.0f} % of a core', flush=True)


if __name__ == '__main__':
    main()
