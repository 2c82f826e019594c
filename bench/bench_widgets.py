"""Widget speed: plot redraws per second, what drawing costs the kernel, slider round trips.

Runs a real sensor (50 Hz) and controller in their own processes, then measures in this
process (as a kernel would run them):
- render: one frame of a two-topic plot (blitted lines + PNG), ms;
- live: redraws/s the plot's own thread achieves when asked for 20 and for 60;
- kernel: how late a 10 ms sleep on the main thread wakes up, without and with a live plot
  drawing at 15 fps (the kernel's responsiveness while the plot runs);
- slider: one `Sliders.set()` round trip through the node's set_parameters service, ms.
Each number is the median of several runs. Usage: python bench/bench_widgets.py [--runs N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault('ROS_DOMAIN_ID', '95')
os.environ['ROBOT_LAB_HEADLESS'] = '1'


def _start_nodes() -> list[object]:
    from robot_lab.env import ros_environment
    from robot_lab.process import spawn

    cli = str(Path(sys.executable).parent / 'robot-lab')
    env = ros_environment()
    return [
        spawn([cli, 'run', 'robot_lab', 'sensor_node', '--ros-args', '-r', '__node:=sensor',
               '-p', 'sensor_rate:=50'], env=env),
        spawn([cli, 'run', 'robot_lab', 'controller_node', '--ros-args',
               '-r', '__node:=controller'], env=env),
    ]


def _late_wakeups(seconds: float) -> float:
    """Median lateness (ms) of 10 ms sleeps on this thread over `seconds`."""
    late = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        before = time.monotonic()
        time.sleep(0.010)
        late.append((time.monotonic() - before - 0.010) * 1000)
    return statistics.median(late)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=5)
    runs = parser.parse_args().runs

    from robot_lab.process import stop
    from robot_lab.widgets.plot import Plot
    from robot_lab.widgets.sliders import Sliders

    procs = _start_nodes()
    try:
        plot = Plot('/sensor/temperature', '/cmd_vel/linear/x', window=10.0, timeout=20.0)
        plot.wait_for_samples(50, timeout=20.0)
        plot.render_png()  # the first frame builds the figure
        frames = []
        for _ in range(runs * 20):
            t = time.perf_counter()
            plot.render_png()
            frames.append((time.perf_counter() - t) * 1000)
        frame = statistics.median(frames)
        print(f'render: {frame:.1f} ms per frame (median of {len(frames)}; '
              f'{1000 / frame:.0f} frames/s possible)')
        plot.close()

        for fps in (20.0, 60.0):
            rates = []
            for _ in range(runs):
                live = Plot('/sensor/temperature', '/cmd_vel/linear/x', window=10.0, fps=fps)
                live.start()
                start_count, t = live.redraws, time.monotonic()
                time.sleep(2.0)
                rates.append((live.redraws - start_count) / (time.monotonic() - t))
                live.close()
            print(f'live plot asked for {fps:.0f} fps: {statistics.median(rates):.1f} redraws/s '
                  f'(median of {runs} runs of 2 s)')

        idle = statistics.median(_late_wakeups(1.0) for _ in range(runs))
        busy = []
        for _ in range(runs):
            live = Plot('/sensor/temperature', '/cmd_vel/linear/x', window=10.0, fps=15.0)
            live.start()
            busy.append(_late_wakeups(1.0))
            live.close()
        print(f'kernel: a 10 ms sleep wakes {idle:.2f} ms late idle, '
              f'{statistics.median(busy):.2f} ms late while a plot draws at 15 fps')

        sliders = Sliders('/sensor', timeout=20.0)
        trips = []
        for i in range(runs * 10):
            t = time.perf_counter()
            result = sliders.set('noise_level', 0.1 + (i % 2) * 0.1)
            trips.append((time.perf_counter() - t) * 1000)
            assert result.successful, result
        print(f'slider: set() round trip {statistics.median(trips):.1f} ms '
              f'(median of {len(trips)})')
        sliders.close()
    finally:
        for proc in procs:
            stop(proc)  # type: ignore[arg-type]


if __name__ == '__main__':
    main()
