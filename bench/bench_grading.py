"""How long grading takes: per solution notebook (target ≤ 30 s each), the fixed cost of a
kernel, generating the exercises, and a batch of unanswered exercises graded with -j.

Median over RUNS runs, with the load average (other work on the machine slows kernels).

    .venv/bin/python bench/bench_grading.py [--runs 3] [--domain 96]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import nbformat

from robot_lab.grading.exercises import build_exercises, kit_root
from robot_lab.grading.grade import GradeResult, grade

BIN = Path(sys.executable).parent


def timed(fn: object, runs: int) -> tuple[float, list[float]]:
    times = []
    for _ in range(runs):
        start = time.monotonic()
        fn()  # type: ignore[operator]
        times.append(time.monotonic() - start)
    return statistics.median(times), times


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--domain', type=int, default=96, help='first ROS domain used')
    parser.add_argument('--jobs', type=int, default=4, help='-j for the exercise batch')
    args = parser.parse_args()
    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    root = kit_root()
    print(f'load average at start: {os.getloadavg()[0]:.2f}')

    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / 'empty.ipynb'
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_code_cell('import robot_lab.grading')]
        empty.write_text(nbformat.writes(nb))
        median, _ = timed(lambda: grade(empty), args.runs)
        print(f'kernel start + one cell + shutdown: {median:.2f} s')
        median, _ = timed(lambda: build_exercises(exercises_dir=Path(tmp) / 'ex'), args.runs)
        print(f'exercises build (all solutions): {median:.2f} s')

    for path in sorted((root / 'solutions').glob('*.ipynb')):
        results: list[GradeResult] = []

        def one(path: Path = path, results: list[GradeResult] = results) -> None:
            results.append(grade(path, cell_timeout=60))

        median, times = timed(one, args.runs)
        scores = {r.summary() for r in results}
        runs = ', '.join(f'{t:.1f}' for t in times)
        print(f'{path.stem:26} median {median:5.2f} s  (runs {runs})  {", ".join(sorted(scores))}')

    start = time.monotonic()
    done = subprocess.run(
        [str(BIN / 'robot-lab'), 'grade', str(root / 'exercises'), '-j', str(args.jobs),
         '--domain-id', str(args.domain), '--timeout', '30'],
        capture_output=True, text=True, check=False)
    wall = time.monotonic() - start
    totals = [line for line in done.stdout.splitlines() if line.startswith('ex')][-6:]
    print(f'unanswered exercises, -j {args.jobs}: {wall:.1f} s wall ({"; ".join(totals)})')
    print(f'load average at end: {os.getloadavg()[0]:.2f}')


if __name__ == '__main__':
    main()
