"""How fast `robot-lab launch robot_lab robot.launch.xml` brings the system up (issue 3).

Measured in the same run, median of RUNS runs each:
- bare trio: three bare rclpy processes started together, until each sees the other two
  (the floor any launcher is compared with);
- launch -> first `Status:` line, and its ratio to the bare trio (goal <= 1.4; a real
  `ros2 launch` measures 1.8);
- an observer node started BEFORE the launch: time until it sees /sensor, /controller
  and /robot, from the launcher's start and from the nodes' start (first `process
  started` line) (goal <= 1 s; a real `ros2 launch` takes ~3.6 s here);
- the same with the kit's Fast DDS profile off (a user profile with no settings), to show
  what the profile buys;
- total RSS of launcher + three nodes once the system runs (goal <= 230 MB).

    .venv/bin/python bench/bench_launch.py [--runs 5]

Uses ROS_DOMAIN_ID (default 29) and loopback-only discovery, like everything in the kit.
"""

from __future__ import annotations

import argparse
import os
import queue
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil

from robot_lab.env import ros_environment
from robot_lab.process import spawn, stop

BIN = Path(sys.executable).parent
NODES = ['/sensor', '/controller', '/robot']

# A node that reports (wall clock) when it sees every node named on its command line.
WATCHER = r"""
import sys, time
import rclpy
from rclpy.signals import SignalHandlerOptions
rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
name, wanted = sys.argv[1], set(sys.argv[2:])
node = rclpy.create_node(name)
print('ready', time.time(), flush=True)
while True:
    names = {ns.rstrip('/') + '/' + n for n, ns in node.get_node_names_and_namespaces()}
    if wanted <= names:
        print('seen', time.time(), flush=True)
        break
    time.sleep(0.002)
try:
    time.sleep(60)
except KeyboardInterrupt:
    pass
"""

EMPTY_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles/></dds>
"""


class Lines:
    """A child's output lines with the wall-clock time each arrived."""

    def __init__(self, proc: subprocess.Popen[bytes]) -> None:
        self.proc = proc
        self.queue: queue.Queue[tuple[float, str] | None] = queue.Queue()
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for raw in iter(self.proc.stdout.readline, b''):
            self.queue.put((time.time(), raw.decode(errors='replace').rstrip('\n')))
        self.queue.put(None)

    def until(self, needle: str, timeout: float = 30.0) -> tuple[float, str]:
        deadline = time.monotonic() + timeout
        while True:
            item = self.queue.get(timeout=max(0.01, deadline - time.monotonic()))
            if item is None:
                raise RuntimeError(f'{self.proc.args!r} ended before printing {needle!r}')
            if needle in item[1]:
                return item


def watcher(name: str, wanted: list[str],
            env: dict[str, str]) -> tuple[subprocess.Popen[bytes], Lines]:
    proc = spawn([sys.executable, '-c', WATCHER, name, *wanted], env=env)
    return proc, Lines(proc)


def bare_trio(env: dict[str, str]) -> float:
    """Seconds from starting three bare rclpy processes until all three saw each other."""
    names = ['bare_a', 'bare_b', 'bare_c']
    began = time.time()
    started = [watcher(n, [f'/{o}' for o in names if o != n], env) for n in names]
    try:
        return max(float(lines.until('seen')[1].split()[1]) for _, lines in started) - began
    finally:
        for proc, _ in started:
            stop(proc, 2, 2)


def launch_run(env: dict[str, str]) -> dict[str, float]:
    """One launch with an observer started first; times and the RSS of the system."""
    observer, seen = watcher('observer', NODES, env)
    seen.until('ready')
    began = time.time()
    launcher = spawn([str(BIN / 'robot-lab'), 'launch', 'robot_lab', 'robot.launch.xml'], env=env)
    out = Lines(launcher)
    try:
        first_start = out.until('process started with pid')[0]
        up: list[float] = []
        status = 0.0
        while not status:  # the three nodes' "... started" lines, then the first Status:
            stamp, line = out.until(']: ')
            if 'node started' in line:
                up.append(stamp)
            elif 'Status:' in line:
                status = stamp
        while len(up) < 3:
            up.append(out.until('node started')[0])
        all_seen = float(seen.until('seen')[1].split()[1])
        system = [psutil.Process(launcher.pid), *psutil.Process(launcher.pid).children(True)]
        rss = sum(p.memory_info().rss for p in system) / 2**20
        return {
            'status': status - began,
            'seen_from_launch': all_seen - began,
            'seen_from_nodes': all_seen - first_start,
            'seen_from_last_up': all_seen - max(up),
            'rss': rss,
            'launcher_rss': system[0].memory_info().rss / 2**20,
        }
    finally:
        stop(launcher, 5, 5)
        stop(observer, 2, 2)


def median(runs: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=5)
    args = parser.parse_args()
    env = ros_environment({'ROS_DOMAIN_ID': os.environ.get('ROS_DOMAIN_ID', '29')})
    with tempfile.TemporaryDirectory() as tmp:
        env['ROS_LOG_DIR'] = tmp
        profile = Path(tmp) / 'empty_profile.xml'
        profile.write_text(EMPTY_PROFILE)
        env_off = dict(env, FASTRTPS_DEFAULT_PROFILES_FILE=str(profile))
        bare, launched, bare_off, launched_off = [], [], [], []
        for _ in range(args.runs):
            bare.append(bare_trio(env))
            launched.append(launch_run(env))
            bare_off.append(bare_trio(env_off))
            launched_off.append(launch_run(env_off))

    trio = statistics.median(bare)
    rows = [
        ('bare trio: three rclpy processes see each other', f'{trio:.2f} s', ''),
        ('launch -> first Status: line', f'{median(launched, "status"):.2f} s', ''),
        ('  ratio to bare trio', f'{median(launched, "status") / trio:.2f}', '<= 1.4'),
        ('observer (started first) sees all 3 nodes, from launch',
         f'{median(launched, "seen_from_launch"):.2f} s', ''),
        ("observer sees all 3 nodes, from the nodes' start",
         f'{median(launched, "seen_from_nodes"):.2f} s', '<= 1 s'),
        ('observer sees all 3 nodes, after the last node is up',
         f'{median(launched, "seen_from_last_up"):.2f} s', ''),
        ('RSS launcher + 3 nodes', f'{median(launched, "rss"):.0f} MB', '<= 230 MB'),
        ('  of which the launcher', f'{median(launched, "launcher_rss"):.0f} MB', ''),
        ('-- kit Fast DDS profile off --', '', ''),
        ('bare trio', f'{statistics.median(bare_off):.2f} s', ''),
        ('launch -> first Status: line', f'{median(launched_off, "status"):.2f} s', ''),
        ('observer sees all 3 nodes, from launch',
         f'{median(launched_off, "seen_from_launch"):.2f} s', ''),
        ("observer sees all 3 nodes, from the nodes' start",
         f'{median(launched_off, "seen_from_nodes"):.2f} s', ''),
        ('observer sees all 3 nodes, after the last node is up',
         f'{median(launched_off, "seen_from_last_up"):.2f} s', ''),
    ]
    width = max(len(r[0]) for r in rows)
    print(f'robot-lab launch robot_lab robot.launch.xml, median of {args.runs} runs '
          f'(ROS_DOMAIN_ID={env["ROS_DOMAIN_ID"]})')
    for name, value, goal in rows:
        print(f'{name:<{width}}  {value:>8}  {goal}')
    print('all runs (status / seen from launch / from nodes / after last up, s; RSS MB):')
    for label, runs in (('profile on ', launched), ('profile off', launched_off)):
        print(f'  {label}: ' + ', '.join(
            f'{r["status"]:.2f}/{r["seen_from_launch"]:.2f}/{r["seen_from_nodes"]:.2f}/'
            f'{r["seen_from_last_up"]:.2f}/{r["rss"]:.0f}' for r in runs))
    print('bare trio runs (on/off): ' + ', '.join(f'{a:.2f}/{b:.2f}'
                                                 for a, b in zip(bare, bare_off, strict=True)))


if __name__ == '__main__':
    main()
