"""How long nbval takes over the notebooks (issue 22: goal <= 90 s for all of them): the
time per notebook (kernel start, every cell, shutdown) and in total, median over RUNS runs
of `pytest notebooks --nbval-lax` with `./kit test`'s nbval flags, one notebook at a time
(`-n 0`), and the slowest cells. Each run prints the host's load average, since the
notebooks wait on real processes and a busy host stretches every number.

Each run starts as `./kit test` does: test-run domains and a fresh workspace, so notebook
01 creates the package and `colcon build` builds it alone. (Before, the runs shared
~/robot_lab_ws: 01's build built every package the later notebooks had left there, and its
`ros2 run` found a sensor written by an earlier run and ran it for the whole 5 s.)

    .venv/bin/python bench/bench_nbval.py [--runs 3] [NOTEBOOK ...]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# As `./kit test` runs them (kit: the `test` verb).
NBVAL_FLAGS = ['--nbval-lax', '--nbval-cell-timeout', '280',
               '--nbval-sanitize-with', 'notebooks/nbval_sanitize.cfg']
_DURATION = re.compile(r'^(?P<secs>[\d.]+)s (?P<phase>setup|call|teardown)\s+'
                       r'notebooks/(?P<nb>[^:]+)::(?P<cell>Cell \d+)')
_RESULT = re.compile(r'^=*\s*(?P<summary>\d+ passed.*|.*failed.*)\s*=*$')


def _load() -> str:
    return ' '.join(f'{x:.2f}' for x in os.getloadavg())


def one_run(notebooks: list[str]) -> tuple[dict[str, float], dict[str, float], float, str]:
    """Seconds per notebook, per cell ('nb::Cell n'), the wall time and pytest's summary."""
    cmd = [sys.executable, '-m', 'pytest', *notebooks, *NBVAL_FLAGS, '-n', '0',
           '--durations=0', '--durations-min=0', '-p', 'no:randomly', '-q']
    workspace = tempfile.mkdtemp(prefix='bench_nbval_ws_')
    env = dict(os.environ, PATH=f'{Path(sys.executable).parent}{os.pathsep}{os.environ["PATH"]}',
               ROBOT_LAB_WORKSPACE=workspace)
    env.setdefault('ROBOT_LAB_TEST_DOMAIN_BASE', '0')
    began = time.monotonic()
    try:
        done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False,
                              env=env)
    finally:
        shutil.rmtree(workspace, ignore_errors=True)
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
    parser.add_argument('--slowest', type=int, default=12, help='cells to list')
    parser.add_argument('notebooks', nargs='*', default=['notebooks'])
    args = parser.parse_args()
    runs = []
    for index in range(1, args.runs + 1):
        before = _load()
        notebooks, cells, wall, summary = one_run(args.notebooks)
        runs.append((notebooks, cells, wall))
        print(f'run {index}/{args.runs}: {sum(notebooks.values()):.1f} s in nbval items, '
              f'{wall:.1f} s wall ({summary}); load average {before} -> {_load()}', flush=True)
    names = sorted({name for notebooks, _, _ in runs for name in notebooks})
    print(f'\nnbval, median of {len(runs)} run(s), seconds per notebook:')
    for name in names:
        print(f'  {statistics.median(r[0].get(name, 0.0) for r in runs):7.1f}  {name}')
    total = statistics.median(sum(r[0].values()) for r in runs)
    print(f'  {total:7.1f}  total (goal <= 90 s); wall '
          f'{statistics.median(r[2] for r in runs):.1f} s')
    every_cell = {cell for _, per_cell, _ in runs for cell in per_cell}
    slowest = sorted(((statistics.median(r[1].get(cell, 0.0) for r in runs), cell)
                      for cell in every_cell), reverse=True)[:args.slowest]
    print('slowest cells (median s):')
    for secs, cell in slowest:
        print(f'  {secs:7.2f}  {cell}')


if __name__ == '__main__':
    main()
