"""How long nbval takes over the notebooks (issue 22: goal <= 90 s for all of them), run as
`./kit test notebooks` runs them: lessons 01-06 in order on one worker (each builds on the
package the one before left), the lessons that stand alone (00, 07-10) beside them on the
others (`--workers`, the kit's 4 by default; `--workers 0`: one notebook at a time). It
prints the wall time of the command, the time per notebook (kernel start, every cell,
shutdown), the median over RUNS runs, and the slowest cells. Each run prints the host's load
average, since the notebooks wait on real processes and a busy host stretches every number.

Each run starts as `./kit test` does: test-run domains and, per worker, a fresh workspace
(tests/conftest.py), so notebook 01 creates the package and `colcon build` builds it alone.
(Before session 19 the runs shared ~/robot_lab_ws: 01's build built every package the later
notebooks had left there, and its `ros2 run` found a sensor an earlier run had written.)

    .venv/bin/python bench/bench_nbval.py [--runs 3] [--workers 4] [--busy 0] [NOTEBOOK ...]
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

from busy import busy_loops

ROOT = Path(__file__).resolve().parent.parent
_DURATION = re.compile(r'^(?P<secs>[\d.]+)s (?P<phase>setup|call|teardown)\s+'
                       r'notebooks/(?P<nb>[^:]+)::(?P<cell>Cell \d+)')
_RESULT = re.compile(r'^=*\s*(?P<summary>\d+ passed.*|.*failed.*)\s*=*$')


def _load() -> str:
    return ' '.join(f'{x:.2f}' for x in os.getloadavg())


def one_run(notebooks: list[str], workers: int
            ) -> tuple[dict[str, float], dict[str, float], float, str]:
    """Seconds per notebook, per cell ('nb::Cell n'), the wall time and pytest's summary."""
    cmd = [str(ROOT / 'kit'), 'test', *notebooks, '--durations=0', '--durations-min=0', '-q']
    env = dict(os.environ, ROBOT_LAB_TEST_WORKERS=str(workers))
    env.setdefault('ROBOT_LAB_TEST_DOMAIN_BASE', '0')
    began = time.monotonic()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False, env=env)
    wall = time.monotonic() - began
    per_notebook: dict[str, float] = defaultdict(float)
    per_cell: dict[str, float] = defaultdict(float)
    summary = 'no summary'
    for line in done.stdout.splitlines():
        if (m := _DURATION.match(line)) is not None:
            per_notebook[m['nb']] += float(m['secs'])
            if m['phase'] == 'call':
                per_cell[f"{m['nb']}::{m['cell']}"] = float(m['secs'])
        elif (r := _RESULT.match(line)) is not None:
            summary = r['summary']
    if done.returncode != 0:
        print(done.stdout[-3000:], file=sys.stderr)
    return dict(per_notebook), dict(per_cell), wall, summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--workers', type=int, default=4,
                        help='pytest-xdist workers, as `./kit test` (0: one notebook at a time)')
    parser.add_argument('--busy', type=int, default=0, help='busy loops beside the runs')
    parser.add_argument('--slowest', type=int, default=12, help='cells to list')
    parser.add_argument('notebooks', nargs='*', default=['notebooks'])
    args = parser.parse_args()
    runs = []
    for index in range(1, args.runs + 1):
        before = _load()
        with busy_loops(args.busy):
            notebooks, cells, wall, summary = one_run(args.notebooks, args.workers)
        runs.append((notebooks, cells, wall))
        print(f'run {index}/{args.runs}: {sum(notebooks.values()):.1f} s in nbval items, '
              f'{wall:.1f} s wall ({summary}); load average {before} -> {_load()}', flush=True)
    names = sorted({name for notebooks, _, _ in runs for name in notebooks})
    print(f'\nnbval on {args.workers or "no"} workers, {args.busy} busy loops, median of '
          f'{len(runs)} run(s), seconds per notebook:')
    for name in names:
        print(f'  {statistics.median(r[0].get(name, 0.0) for r in runs):7.1f}  {name}')
    total = statistics.median(sum(r[0].values()) for r in runs)
    print(f'  {total:7.1f}  total, one after another')
    print(f'  {statistics.median(r[2] for r in runs):7.1f}  wall: `./kit test notebooks` from '
          'start to end (goal <= 90 s)')
    every_cell = {cell for _, per_cell, _ in runs for cell in per_cell}
    slowest = sorted(((statistics.median(r[1].get(cell, 0.0) for r in runs), cell)
                      for cell in every_cell), reverse=True)[:args.slowest]
    print('slowest cells (median s):')
    for secs, cell in slowest:
        print(f'  {secs:7.2f}  {cell}')


if __name__ == '__main__':
    main()
