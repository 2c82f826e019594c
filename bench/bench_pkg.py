"""How long the package workflow takes (issue 5): pkg create, a cold `colcon build` of one
package, a rebuild after an edit, use_workspace, doctor on a package and on the
environment. Median over RUNS runs, each in a fresh temporary workspace.

    .venv/bin/python bench/bench_pkg.py [--runs 5]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from robot_lab.pkg.build import build
from robot_lab.pkg.create import create_package
from robot_lab.pkg.doctor import doctor
from robot_lab.pkg.workspace import use_workspace


def _timed(fn: Callable[[], object]) -> float:
    began = time.perf_counter()
    fn()
    return time.perf_counter() - began


def one_run() -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        ws = Path(tmp)
        times: dict[str, float] = {}
        times['pkg create'] = _timed(lambda: create_package(
            'bench_pkg', ws / 'src', dependencies=['rclpy', 'std_msgs'], node_name='talker',
            with_launch=True, with_config=True))
        times['build (cold)'] = _timed(lambda: build(ws, progress=False))
        node = ws / 'src' / 'bench_pkg' / 'bench_pkg' / 'talker.py'
        node.write_text(node.read_text().replace('Hi', 'Hello'))
        times['build (after edit)'] = _timed(lambda: build(ws, progress=False))
        times['use_workspace'] = _timed(lambda: use_workspace(ws))
        times['doctor package'] = _timed(lambda: doctor(ws / 'src' / 'bench_pkg'))
        times['doctor environment'] = _timed(lambda: doctor())
        return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--runs', type=int, default=5)
    args = parser.parse_args()
    runs = [one_run() for _ in range(args.runs)]
    print(f'median of {args.runs} runs')
    for key in runs[0]:
        values = [run[key] for run in runs]
        print(f'{key:22s} {statistics.median(values) * 1000:8.0f} ms  '
              f'(min {min(values) * 1000:.0f}, max {max(values) * 1000:.0f})')


if __name__ == '__main__':
    main()
