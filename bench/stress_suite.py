"""Run the suite (or some modules) N times beside busy loops; print the failures per test.

A race between a test and DDS discovery shows up on a loaded host, once in many runs: a
single green run proves little. This runs pytest RUNS times, each with BUSY processes
spinning on the CPU beside it (as a class hub is loaded), and prints for every test that
failed at least once how often it did, with the first line of its last failure, and each
run's duration and result.

    .venv/bin/python bench/stress_suite.py --runs 10 [--busy 2] [--workers 3] \\
        [tests/test_tutorials.py tests/test_graph_daemon.py ...] [-- PYTEST ARGS]
    ./kit test --stress 10 [modules...]

Without modules it runs what `./kit test` runs (tests/, the notebooks in Chromium). Exit
code 1 if any run failed. Run it in a private network namespace and /dev/shm (`unshare --net
--mount`, `lo` up, a tmpfs on /dev/shm) when other DDS traffic shares the host; a second
test run in the same ones is refused (tests/conftest.py).
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

from busy import busy_loops

ROOT = Path(__file__).resolve().parent.parent


def failures(junit: Path) -> dict[str, str]:
    """test id -> first line of its failure or error, from one run's JUnit XML."""
    if not junit.is_file():
        return {}
    found: dict[str, str] = {}
    for case in ET.parse(junit).iter('testcase'):
        for problem in (*case.iter('failure'), *case.iter('error')):
            text = (problem.get('message') or problem.text or problem.tag).strip()
            test = f'{case.get("classname", "")}::{case.get("name", "")}'
            found[test] = (text.splitlines() or [problem.tag])[0][:160]
    return found


def pytest_command(modules: list[str], workers: int, extra: list[str], junit: Path) -> list[str]:
    python = sys.executable
    targets = modules or ['tests']  # as `./kit test` with Chromium: notebooks in tests/browser
    cmd = [python, '-m', 'pytest', *targets, '-q', f'--junitxml={junit}']
    if workers > 0:
        cmd += ['-n', str(workers), '--dist', 'loadscope']
    return cmd + extra


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    extra: list[str] = []
    if '--' in argv:
        extra = argv[argv.index('--') + 1:]
        argv = argv[:argv.index('--')]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=10)
    parser.add_argument('--busy', type=int, default=2, help='busy loops beside each run')
    parser.add_argument('--workers', type=int,
                        default=int(os.environ.get('ROBOT_LAB_TEST_WORKERS', '4')))
    parser.add_argument('modules', nargs='*', help='test modules (default: the whole suite)')
    args = parser.parse_args(argv)
    env = {**os.environ, 'PATH': f'{Path(sys.executable).parent}:{os.environ["PATH"]}'}
    env.setdefault('ROBOT_LAB_TEST_DOMAIN_BASE', '0')
    counts: collections.Counter[str] = collections.Counter()
    last: dict[str, str] = {}
    runs: list[str] = []
    with tempfile.TemporaryDirectory(prefix='robot_lab-stress-') as tmp:
        for index in range(1, args.runs + 1):
            junit = Path(tmp) / f'run{index}.xml'
            started = time.monotonic()
            with busy_loops(args.busy):
                done = subprocess.run(pytest_command(args.modules, args.workers, extra, junit),
                                      cwd=ROOT, env=env, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, text=True, check=False)
            took = time.monotonic() - started
            failed = failures(junit)
            counts.update(failed.keys())
            last.update(failed)
            summary = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ''
            runs.append(f'run {index}: exit {done.returncode}, {took / 60:.1f} min, '
                        f'{len(failed)} failed  {summary}')
            print(runs[-1], flush=True)
    print(f'\n{args.runs} runs with {args.busy} busy loops, {args.workers} workers '
          f'({os.cpu_count()} cores)')
    if not counts:
        print('no test failed')
        return 0
    print('failures per test:')
    for test, count in counts.most_common():
        print(f'  {count}/{args.runs}  {test}\n        {last[test]}')
    return 1


if __name__ == '__main__':
    sys.exit(main())
