"""Graph inspection timings and `topic hz` accuracy (issue 4). Prints a table of medians.

- `robot-lab node list` end to end as a cold process (system already up), and how often
  its answer was complete;
- `robot-lab launch robot_lab robot.launch.xml` -> all three nodes seen by a warm session
  (process start + discovery), and `robot-lab node list` started 0/0.25/0.5/1 s after the
  launch: complete or partial, and when it printed (median and worst) — with a daemon
  already warm (as `./kit start` keeps one), with the one the launch starts, and with none;
  `robot-lab node list` answered by the launch's daemon once the system is up;
- `node_list()` on a warm session; parameter set round trip (warm API and cold CLI);
- `topic_hz` at 10/50/100 Hz (sensor started with -p sensor_rate:=N) and the CLI's
  `topic hz --window 20 --duration 4` at 10 Hz.

    .venv/bin/python bench/bench_graph.py [--runs 5]

Uses ROS_DOMAIN_ID 59 unless set (keep benchmarks off other people's domains).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

os.environ.setdefault('ROS_DOMAIN_ID', '59')

import robot_lab
from robot_lab.env import ros_environment
from robot_lab.process import spawn, stop
from robot_lab.rclpy_session import session

BIN = Path(sys.executable).parent
CLI = str(BIN / 'robot-lab')
SEED = ['/controller', '/robot', '/sensor']


def start_system(sensor_rate: int | None = None,
                 only: Sequence[str] = ('sensor', 'controller', 'robot'),
                 ) -> list[subprocess.Popen[bytes]]:
    procs = []
    for name in only:
        extra = ['-p', f'sensor_rate:={sensor_rate}'] if sensor_rate and name == 'sensor' else []
        procs.append(spawn([CLI, 'run', 'robot_lab', f'{name}_node', '--ros-args', '-r',
                            f'__node:={name}', *extra], env=ros_environment(),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    return procs


def stop_all(procs: list[subprocess.Popen[bytes]]) -> None:
    for proc in procs:
        stop(proc)


def _env(daemon: bool) -> dict[str, str]:
    return ros_environment(None if daemon else {'ROBOT_LAB_NO_DAEMON': '1'})


def cli(*args: str, daemon: bool = True) -> tuple[float, str]:
    start = time.monotonic()
    out = subprocess.run([CLI, *args], capture_output=True, text=True, check=False,
                         env=_env(daemon), timeout=60).stdout
    return time.monotonic() - start, out


def timed(fn: Callable[[], object], runs: int) -> float:
    samples = []
    for _ in range(runs):
        start = time.monotonic()
        fn()
        samples.append(time.monotonic() - start)
    return statistics.median(samples)


def launch(daemon: bool = True) -> subprocess.Popen[bytes]:
    return spawn([CLI, 'launch', 'robot_lab', 'robot.launch.xml'], env=_env(daemon),
                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def wait_empty() -> None:
    while robot_lab.node_list(settle=False):
        time.sleep(0.1)  # the next run starts from an empty graph
    # ...and not within milliseconds of the last one ending: participants that have just
    # left are still being cleaned up, and a person does not relaunch that fast.
    time.sleep(1.0)


def node_list_after_launch(delay: float, runs: int,
                           daemon: bool = True) -> tuple[int, float, float]:
    """`robot-lab node list` started `delay` s after `robot-lab launch`: (complete runs,
    median and worst s from launch start to its output)."""
    complete, done = 0, []
    for _ in range(runs):
        start = time.monotonic()
        proc = launch(daemon)
        try:
            time.sleep(delay)  # the schedule being measured, not a synchronisation
            _, out = cli('node', 'list', daemon=daemon)
            done.append(time.monotonic() - start)
            complete += out.split() == SEED
        finally:
            stop(proc)
        wait_empty()
    return complete, statistics.median(done), max(done)


@contextlib.contextmanager
def warm_daemon() -> Iterator[None]:
    """A daemon started before the launches (as `./kit start` does), ended after them."""
    from robot_lab.graph import daemon

    daemon.wait_until_running(proc=daemon.start(detached=True, owner=os.getpid()))
    try:
        yield
    finally:
        daemon.stop()


def daemon_node_list(runs: int) -> float:
    """Median s of `robot-lab node list` answered by a running launch's daemon."""
    proc = launch()
    try:
        robot_lab.wait_for_nodes(SEED, timeout=15)
        while cli('node', 'list')[1].split() != SEED:
            pass  # until the daemon has the whole graph
        return statistics.median(cli('node', 'list')[0] for _ in range(runs))
    finally:
        stop(proc)
        wait_empty()


def warm_discovery(runs: int) -> float:
    """s from `robot-lab launch` until a warm session lists all three nodes."""
    samples = []
    for _ in range(runs):
        start = time.monotonic()
        proc = launch()
        try:
            robot_lab.wait_for_nodes(SEED, timeout=15)
            samples.append(time.monotonic() - start)
        finally:
            stop(proc)
        wait_empty()
    return statistics.median(samples)


def hz_error(rate: int, runs: int, duration: float) -> tuple[float, float]:
    """(median measured rate, median |error| %) of topic_hz against the configured rate."""
    procs = start_system(sensor_rate=rate, only=('sensor',))
    try:
        robot_lab.wait_for_nodes(['/sensor'], timeout=10)
        robot_lab.echo('/sensor/temperature', count=2, timeout=10)
        rates = [robot_lab.topic_hz('/sensor/temperature', duration=duration).rate
                 for _ in range(runs)]
    finally:
        stop_all(procs)
    med = statistics.median(rates)
    return med, statistics.median(abs(r - rate) / rate * 100 for r in rates)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=5)
    parser.add_argument('--hz-duration', type=float, default=5.0)
    args = parser.parse_args()
    rows: list[tuple[str, str]] = []
    sess = session()

    procs = start_system()
    try:
        robot_lab.wait_for_nodes(SEED, timeout=15)
        cold = [cli('node', 'list') for _ in range(args.runs)]
        complete = sum(out.split() == SEED for _, out in cold)
        rows.append(('robot-lab node list, cold process (system up)',
                     f'{statistics.median(t for t, _ in cold):.2f} s '
                     f'({complete}/{len(cold)} complete)'))
        sess_age = time.monotonic() - sess.created
        rows.append((f'node_list() warm session (age {sess_age:.0f} s)',
                     f'{timed(robot_lab.node_list, 30) * 1000:.1f} ms'))
        rows.append(('node_list(settle=False) warm session',
                     f'{timed(lambda: robot_lab.node_list(settle=False), 30) * 1000:.2f} ms'))
        robot_lab.param_get('/sensor', 'noise_level')
        values = iter([0.1, 0.2] * 100)
        rows.append(('param_set() round trip, warm session',
                     f'{timed(lambda: robot_lab.param_set("/sensor", "noise_level", next(values)), 50) * 1000:.2f} ms'))  # noqa: E501
        rows.append(('robot-lab param set, cold process',
                     f'{statistics.median(cli("param", "set", "/sensor", "noise_level", "0.1")[0] for _ in range(args.runs)):.2f} s'))  # noqa: E501
        hz_out = cli('topic', 'hz', '/sensor/temperature', '--window', '20', '--duration', '4')[1]
        last = re.findall(r'^average rate: (\S+)$', hz_out, re.M)
        rows.append(('robot-lab topic hz --window 20 --duration 4 (10 Hz)',
                     f'{last[-1] if last else "no output"} Hz'))
    finally:
        stop_all(procs)
    wait_empty()

    rows.append(('robot-lab launch -> warm session sees all three',
                 f'{warm_discovery(args.runs):.2f} s'))
    rows.append(("robot-lab node list answered by the launch's daemon",
                 f'{daemon_node_list(args.runs):.2f} s'))
    for mode in ('warm daemon', "launch's daemon", 'no daemon'):
        with warm_daemon() if mode == 'warm daemon' else contextlib.nullcontext():
            for delay in (0.0, 0.25, 0.5, 1.0):
                complete, done, worst = node_list_after_launch(delay, args.runs,
                                                               mode != 'no daemon')
                rows.append((f'node list started {delay:g} s after launch, {mode}',
                             f'{complete}/{args.runs} complete, printed at {done:.2f} s '
                             f'(worst {worst:.2f})'))

    for rate in (10, 50, 100):
        measured, err = hz_error(rate, max(3, args.runs // 2), args.hz_duration)
        rows.append((f'topic_hz() at {rate} Hz ({args.hz_duration:g} s)',
                     f'{measured:.3f} Hz (error {err:.2f} %)'))

    width = max(len(name) for name, _ in rows)
    print(f'{"measure (median of runs)":<{width}}  value')
    print(f'{"-" * width}  {"-" * 30}')
    for name, value in rows:
        print(f'{name:<{width}}  {value}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
