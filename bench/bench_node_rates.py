"""Achieved vs configured publish rate of the reference nodes (issue 2).

For each case the node runs as a real process (`robot-lab run`), an in-process subscriber
records receive times for DURATION seconds, and we report the mean rate error (%) and
the jitter (std of inter-arrival gaps, ms). Median over RUNS runs.

    .venv/bin/python bench/bench_node_rates.py [--runs 5] [--duration 3]
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

os.environ.setdefault('ROS_DOMAIN_ID', '97')

from robot_lab.env import ros_environment
from robot_lab.messages import message_class
from robot_lab.process import spawn, stop
from robot_lab.rclpy_session import session

BIN = Path(sys.executable).parent
CASES = [
    ('sensor_node', 'sensor_rate', 10, '/sensor/temperature', 'std_msgs/msg/Float32'),
    ('sensor_node', 'sensor_rate', 50, '/sensor/temperature', 'std_msgs/msg/Float32'),
    ('sensor_node', 'sensor_rate', 100, '/sensor/temperature', 'std_msgs/msg/Float32'),
    ('controller_node', 'control_rate', 20, '/robot/status', 'std_msgs/msg/String'),
]


def measure(executable: str, param: str, rate: int, topic: str, type_name: str,
            duration: float) -> tuple[float, float]:
    stamps: list[float] = []
    first = threading.Event()

    def on_msg(_msg: object) -> None:
        stamps.append(time.monotonic())
        first.set()

    node = session().node
    sub = node.create_subscription(message_class(type_name), topic, on_msg, 100)
    proc = spawn([str(BIN / 'robot-lab'), 'run', 'robot_lab', executable, '--ros-args',
                  '-p', f'{param}:={rate}'], env=ros_environment(),
                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        if not first.wait(20):
            raise RuntimeError(f'{executable}: no message on {topic}')
        start = len(stamps)
        deadline = time.monotonic() + duration
        while time.monotonic() < deadline:
            first.clear()
            first.wait(deadline - time.monotonic())
        window = stamps[start:]
    finally:
        stop(proc)
        node.destroy_subscription(sub)
    gaps = [b - a for a, b in itertools.pairwise(window)]
    achieved = len(gaps) / sum(gaps)
    return 100.0 * (achieved - rate) / rate, statistics.pstdev(gaps) * 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--runs', type=int, default=5)
    parser.add_argument('--duration', type=float, default=3.0)
    opts = parser.parse_args()
    print(f'{"node":16} {"configured":>10} {"rate error %":>13} {"jitter ms":>10}   (median of '
          f'{opts.runs} runs x {opts.duration:g} s)')
    for executable, param, rate, topic, type_name in CASES:
        errors, jitters = [], []
        for _ in range(opts.runs):
            err, jit = measure(executable, param, rate, topic, type_name, opts.duration)
            errors.append(err)
            jitters.append(jit)
        print(f'{executable:16} {rate:>7} Hz {statistics.median(errors):>+13.2f} '
              f'{statistics.median(jitters):>10.2f}')


if __name__ == '__main__':
    main()
