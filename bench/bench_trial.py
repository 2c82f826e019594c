"""What a `robot_lab.sim.trial` costs: the lesson's check and `sim_behaviour` wait on it.

A Chapter 6 stop controller (a node of this process, answering each /scan) against the
kit's sample robot, a wall 1 m ahead of the lidar. Medians of `--runs` runs of:
- start: the referee (simulator + robot) and the trial's bridge up and connected;
- run: one stop run, from `run()` to its result (the robot stopped and rested 0.5 s):
  free at 1x real time (what a student's notebook sees), free at 4x, and in lockstep at
  20x (the grader's way: each scan waits for the controller's answer);
- the stop distance of each, and whether a trial's runs agree to the bit (every sample).

Run it in its own network namespace: `unshare --net --mount sh -c 'ip link set lo up &&
mount -t tmpfs tmpfs /dev/shm && ROS_DOMAIN_ID=7 .venv/bin/python bench/bench_trial.py'`.

Measured 2026-12-06 on this 2-core host, load average 21 (seven other sessions), 3 runs:
  free 1x       start 2.31 s  run 3.16 s wall for 3.15 s sim  stopped at 0.3054/0.3063/0.3058 m
  free 4x       start 2.00 s  run 0.80 s wall for 3.15 s sim  stopped at 0.3052/0.3053/0.3061 m
  lockstep 20x  start 2.94 s  run 0.21 s wall for 3.21 s sim  stopped at 0.3057 m x3, every
                sample identical (free runs differ by the controller's latency: up to 1 mm)
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any


def _controller(name: str) -> Any:
    from geometry_msgs.msg import Twist
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import LaserScan

    from robot_lab.rclpy_session import session

    class Stopper(Node):
        def __init__(self) -> None:
            super().__init__(name, context=session().context,
                             parameter_overrides=[Parameter('use_sim_time', value=True)])
            self.pub = self.create_publisher(Twist, '/cmd_vel', 10)
            self.create_subscription(LaserScan, '/scan', self.on_scan, 10)

        def on_scan(self, msg: Any) -> None:
            cmd = Twist()
            left = msg.ranges[len(msg.ranges) // 2] - 0.5
            cmd.linear.x = min(0.4, 1.5 * left) if left > 0 else 0.0
            self.pub.publish(cmd)

    return session().add_node(Stopper())


def _trial(speed: float, lockstep: bool, runs: int) -> tuple[float, list[float], list[Any]]:
    from robot_lab.rclpy_session import session
    from robot_lab.sim.trial import Trial

    started = time.monotonic()
    results = []
    walls = []
    with Trial('wall', speed=speed, lockstep=lockstep) as trial:
        start = time.monotonic() - started
        for index in range(runs):
            node = _controller(f'bench_{index}')
            began = time.monotonic()
            results.append(trial.run(sim_seconds=8.0))
            walls.append(time.monotonic() - began)
            session().remove_node(node)
            node.destroy_node()
    return start, walls, results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--runs', type=int, default=3)
    args = parser.parse_args()
    for label, speed, lockstep in (('free 1x', 1.0, False), ('free 4x', 4.0, False),
                                   ('lockstep 20x', 20.0, True)):
        start, walls, results = _trial(speed, lockstep, args.runs)
        gaps = [r.final_distance for r in results]
        same = all(r.samples == results[0].samples for r in results)
        print(f'{label:13s} start {start:5.2f} s   run median {statistics.median(walls):5.2f} s '
              f'wall for {statistics.median(r.sim_seconds for r in results):4.2f} s sim   '
              f'stopped at {", ".join(f"{g:.4f}" for g in gaps)} m   '
              f'runs identical: {same}', flush=True)


if __name__ == '__main__':
    main()
