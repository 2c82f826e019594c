"""What holding `robot_lab.session()` costs a kernel's CPU, per executor.

A JupyterLab kernel with a session, a live plot and parameter sliders used 27-80 % of a
core while the system ran at 10-20 Hz (bench/browser_check.py). This measures the session
part of that in a plain Python process, against the real three-node system
(`robot-lab launch robot_lab robot.launch.xml`, another process):
- idle: the session alone (its hidden node spun in the background);
- subs: plus 2 subscriptions, /sensor/temperature (10 Hz) and /cmd_vel (20 Hz);
- widgets: the sliders of /sensor, /controller and /robot (their parameter clients and
  /parameter_events subscriptions) plus a plot of /sensor/temperature and /cmd_vel
  (subscribed, not drawing: what drawing itself costs does not depend on the executor);
- draw (--draw): widgets with the plot drawing 20 frames a second, for scale.
Each case is measured in a fresh process (process CPU seconds over --seconds, as % of one
core) and the median of --runs runs is printed, with the messages delivered per second (a
cheap executor that drops callbacks would show there) and a slider set() round trip.
`session` is the executor robot_lab.rclpy_session.Session uses now (after), `multi4` the
4-thread pool it used before; `multi2`, `single` and `events` are the other candidates
(rclpy 7.1.5's EventsExecutor spins a whole core while idle and never ran a guard
condition's callback here, so `events` runs end as hung).
Usage: python bench/bench_session.py [--runs N] [--seconds S] [--executors a,b] [--draw]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault('ROS_DOMAIN_ID', '37')
os.environ['ROBOT_LAB_HEADLESS'] = '1'

CASES = ('idle', 'subs', 'widgets')
NODES = ['/sensor', '/controller', '/robot']


def _factories() -> dict[str, Callable[[Any], Any] | None]:
    from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
    from rclpy.experimental.events_executor import EventsExecutor

    return {
        'session': None,  # whatever Session._new_executor makes
        'multi4': lambda ctx: MultiThreadedExecutor(num_threads=4, context=ctx),
        'multi2': lambda ctx: MultiThreadedExecutor(num_threads=2, context=ctx),
        'single': lambda ctx: SingleThreadedExecutor(context=ctx),
        'events': lambda ctx: EventsExecutor(context=ctx),
    }


def _cpu_over(seconds: float) -> float:
    """This process's CPU use over the next `seconds`, in % of one core."""
    cpu, wall = time.process_time(), time.monotonic()
    time.sleep(seconds)
    return 100.0 * (time.process_time() - cpu) / (time.monotonic() - wall)


def _child(executor: str, case: str, seconds: float) -> dict[str, float]:
    """One measurement in this (fresh) process; returns the numbers as a dict."""
    import robot_lab
    from robot_lab.rclpy_session import Session, session

    factory = _factories()[executor]
    if factory is not None:
        Session._new_executor = lambda self: factory(self.context)  # type: ignore[method-assign]
    sess = session()
    robot_lab.wait_for_nodes(NODES, timeout=30)
    result: dict[str, float] = {}
    if case == 'idle':
        time.sleep(1.0)
        result['cpu'] = _cpu_over(seconds)
    elif case == 'subs':
        from geometry_msgs.msg import Twist
        from std_msgs.msg import Float32

        counts = {'/sensor/temperature': 0, '/cmd_vel': 0}

        def counter(topic: str) -> Callable[[Any], None]:
            def _count(_msg: Any) -> None:
                counts[topic] += 1
            return _count

        for topic, cls in (('/sensor/temperature', Float32), ('/cmd_vel', Twist)):
            def _subscribe(topic: str = topic, cls: Any = cls) -> Any:
                return sess.node.create_subscription(cls, topic, counter(topic), 10)
            sess.run_in_executor(_subscribe)
        deadline = time.monotonic() + 20
        while min(counts.values()) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)
        before = sum(counts.values())
        result['cpu'] = _cpu_over(seconds)
        result['msgs_per_s'] = (sum(counts.values()) - before) / seconds
    else:
        from robot_lab.widgets.plot import Plot
        from robot_lab.widgets.sliders import Sliders

        sliders = [Sliders(node, timeout=20.0) for node in NODES]
        plot = Plot('/sensor/temperature', '/cmd_vel/linear/x', window=10.0, fps=20.0,
                    timeout=20.0)
        if not plot.wait_for_samples(3, timeout=20.0):
            raise SystemExit('the plot received no samples')
        if case == 'draw':
            plot.start()
        time.sleep(1.0)
        before = sum(len(s.samples) for s in plot.series)
        result['cpu'] = _cpu_over(seconds)
        result['msgs_per_s'] = (sum(len(s.samples) for s in plot.series) - before) / seconds
        trips = []
        for i in range(10):
            start = time.perf_counter()
            answer = sliders[0].set('noise_level', 0.1 + (i % 2) * 0.1)
            trips.append((time.perf_counter() - start) * 1000)
            if not answer.successful:
                raise SystemExit(f'slider set refused: {answer}')
        result['set_ms'] = statistics.median(trips)
        trips = []
        for _ in range(10):
            start = time.perf_counter()
            robot_lab.param_get('/controller', 'max_speed')
            trips.append((time.perf_counter() - start) * 1000)
        result['get_ms'] = statistics.median(trips)
        plot.close()
        for slider in sliders:
            slider.close()
    return result


def _measure(executor: str, case: str, seconds: float) -> dict[str, float]:
    """One case in a fresh process; NaNs when it failed or hung (the reason is printed)."""
    failed = {'cpu': float('nan'), 'msgs_per_s': float('nan'), 'set_ms': float('nan'),
              'get_ms': float('nan')}
    try:
        done = subprocess.run(
            [sys.executable, __file__, '--child', executor, '--case', case,
             '--seconds', str(seconds)],
            capture_output=True, text=True, timeout=60 + seconds, check=False)
    except subprocess.TimeoutExpired:
        print(f'  {executor}/{case}: no result within {60 + seconds:g} s (hung)')
        return failed
    lines = [line for line in done.stdout.splitlines() if line.startswith('{')]
    if done.returncode != 0 or not lines:
        tail = (done.stdout + done.stderr).strip().splitlines()[-3:]
        print(f'  {executor}/{case}: failed ({done.returncode}): {" | ".join(tail)}')
        return failed
    numbers: dict[str, float] = json.loads(lines[-1])
    return numbers


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--seconds', type=float, default=5.0)
    parser.add_argument('--executors', default='multi4,session')
    parser.add_argument('--draw', action='store_true')
    parser.add_argument('--child', help=argparse.SUPPRESS)
    parser.add_argument('--case', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(_child(args.child, args.case, args.seconds)), flush=True)
        os._exit(0)  # skip rclpy's exit-time teardown: it is not what is measured

    from robot_lab.env import ros_environment
    from robot_lab.process import spawn, stop

    executors = args.executors.split(',')
    unknown = set(executors) - set(_factories())
    if unknown:
        raise SystemExit(f'unknown executor(s): {", ".join(sorted(unknown))}; '
                         f'choose from {", ".join(_factories())}')
    cases = [*CASES, 'draw'] if args.draw else list(CASES)
    cli = str(Path(sys.executable).parent / 'robot-lab')
    system = spawn([cli, 'launch', 'robot_lab', 'robot.launch.xml'], env=ros_environment(),
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results: dict[tuple[str, str], list[dict[str, float]]] = {}
    try:
        for run in range(args.runs):
            # executors interleaved, so the machine's load drifts over all of them alike
            for case in cases:
                for executor in executors:
                    got = _measure(executor, case, args.seconds)
                    results.setdefault((executor, case), []).append(got)
                    print(f'  run {run + 1}: {executor:8} {case:8} {got}', flush=True)
    finally:
        stop(system)
    print(f'\nCPU of the session process, % of one core (median of {args.runs} runs of '
          f'{args.seconds:g} s, failed runs left out; ROS_DOMAIN_ID={os.environ["ROS_DOMAIN_ID"]})')
    print(f'{"executor":16}' + ''.join(f'{case:>10}' for case in cases)
          + f'{"msgs/s":>9}{"set ms":>8}{"get ms":>8}{"failed":>8}')
    labels = {'multi4': 'multi4 (before)', 'session': 'session (now)'}
    for executor in executors:
        row = f'{labels.get(executor, executor):16}'
        for case in cases:
            row += f'{_median(results[executor, case], "cpu"):9.1f}%'
        widgets = results[executor, 'widgets']
        failed = sum(math.isnan(r['cpu']) for case in cases for r in results[executor, case])
        row += (f'{_median(widgets, "msgs_per_s"):9.1f}{_median(widgets, "set_ms"):8.1f}'
                f'{_median(widgets, "get_ms"):8.1f}{failed:8}')
        print(row)


def _median(runs: list[dict[str, float]], key: str) -> float:
    values = [r[key] for r in runs if not math.isnan(r[key])]
    return statistics.median(values) if values else float('nan')

if __name__ == '__main__':
    main()
