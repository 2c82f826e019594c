"""How long `./kit setup` spends building the kit's packages from their definitions, as on
a clean clone (no build folders, no compiler cache): the interface packages one at a time
(lanes 1) against two at a time beside the cache warming (lanes 2, the default).
Median over RUNS runs of each; it rebuilds this venv's kit packages in place.

    .venv/bin/python bench/bench_kit_build.py [--runs 3]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import time
from pathlib import Path

from robot_lab.pkg.kit_packages import _state_dir, build_kit_packages


def one_run(lanes: int) -> float:
    # No build folders, as on a clean clone; `force` also warms the cache again.
    shutil.rmtree(_state_dir(Path(sys.prefix)) / 'build', ignore_errors=True)
    began = time.perf_counter()
    build_kit_packages(force=True, lanes=lanes)
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=3)
    runs = parser.parse_args().runs
    os.environ['CCACHE_DISABLE'] = '1'  # a clean clone has an empty cache
    medians = {}
    for lanes in (1, 2):
        times = [one_run(lanes) for _ in range(runs)]
        medians[lanes] = statistics.median(times)
        print(f'lanes {lanes}: median {medians[lanes]:.1f} s '
              f'({", ".join(f"{t:.1f}" for t in times)})', flush=True)
    print(f'two lanes / one: {medians[2] / medians[1]:.2f}')


if __name__ == '__main__':
    main()
