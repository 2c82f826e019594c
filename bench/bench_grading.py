"""How long grading takes: per solution notebook (target ≤ 30 s each), the fixed cost of a
kernel, generating the exercises, and a batch of unanswered exercises graded with -j;
and for package submissions (issue 12): the median seconds per package at --jobs 1
(aim ≤ 10 s with the sandbox; again beside --busy loops, issue 51), the minutes for a
class of 30 at --jobs 2 (aim ≤ 3 min on 2 cores), and the grader's peak memory (its own
process, and its whole tree of jobs).

Median over RUNS runs, with the load average (other work on the machine slows kernels).

    .venv/bin/python bench/bench_grading.py [--runs 3] [--domain 96] [--only packages] [--busy 3]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import nbformat
import psutil
from busy import busy_loops
from nbclient import NotebookClient

from robot_lab.grading.exercises import build_exercises, kit_root
from robot_lab.grading.notebook.grade import GradeResult, grade

BIN = Path(sys.executable).parent


def timed(fn: object, runs: int) -> tuple[float, list[float]]:
    times = []
    for _ in range(runs):
        start = time.monotonic()
        fn()  # type: ignore[operator]
        times.append(time.monotonic() - start)
    return statistics.median(times), times


def _tree_rss(proc: psutil.Process) -> tuple[int, int]:
    """(RSS of `proc`, RSS of `proc` and all its descendants) in bytes, now."""
    own = total = 0
    with contextlib.suppress(psutil.Error):
        own = total = proc.memory_info().rss
        for child in proc.children(recursive=True):
            with contextlib.suppress(psutil.Error):
                total += child.memory_info().rss
    return own, total


def _without_namespaces(fn: object, runs: int) -> float:
    from robot_lab.grading.package.containment import namespace_problem

    os.environ['ROBOT_LAB_GRADE_NO_NAMESPACES'] = '1'
    namespace_problem.cache_clear()
    try:
        return timed(fn, runs)[0]
    finally:
        del os.environ['ROBOT_LAB_GRADE_NO_NAMESPACES']
        namespace_problem.cache_clear()


def bench_sandbox_cost(args: argparse.Namespace, one: object, sandboxed: float) -> None:
    """What the sandbox costs a student: a job that only enters it (namespaces, read-only
    machine, private /tmp, uid drop) with and without, and a whole package."""
    from robot_lab.grading.package.rubric import Limits
    from robot_lab.grading.package.sandbox import namespaces_available, run_job

    if not namespaces_available():
        print('sandbox cost: no namespaces on this machine (jobs run without the sandbox)')
        return
    enter_only = ('import os\nfrom robot_lab.grading.package.rubric import Limits\n'
                  'from robot_lab.grading.package.sandbox import enter\n'
                  "enter(Limits(), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')))\n")

    def empty_job() -> None:
        with tempfile.TemporaryDirectory() as tmp:
            run_job(Path(tmp), args.domain, Limits(), 'bench-sandbox',
                    argv=['-c', enter_only])

    with_sandbox = timed(empty_job, max(args.runs, 5))[0]
    without = _without_namespaces(empty_job, max(args.runs, 5))
    plain = _without_namespaces(one, args.runs)
    print(f'sandbox cost: {with_sandbox - without:+.2f} s per job to set up '
          f'({with_sandbox:.2f} s vs {without:.2f} s for a job that only enters it); '
          f'a package {sandboxed:.2f} s sandboxed vs {plain:.2f} s without '
          f'({sandboxed - plain:+.2f} s per student)')


def _children_cpu() -> float:
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def bench_fork_cost(args: argparse.Namespace, one: object) -> None:
    """CPU seconds per submission (every process of its job, each reaped by its parent),
    the student's nodes exec'd (ROBOT_LAB_FORK_SERVER=0) against forked from the launcher's
    fork server, runs interleaved so both see the same load."""
    cpu: dict[str, list[float]] = {'0': [], '1': []}
    wall: dict[str, list[float]] = {'0': [], '1': []}
    saved = os.environ.get('ROBOT_LAB_FORK_SERVER')
    try:
        for _ in range(args.runs):
            for mode in ('0', '1'):
                os.environ['ROBOT_LAB_FORK_SERVER'] = mode
                began, used = time.monotonic(), _children_cpu()
                one()  # type: ignore[operator]
                cpu[mode].append(_children_cpu() - used)
                wall[mode].append(time.monotonic() - began)
    finally:
        if saved is None:
            os.environ.pop('ROBOT_LAB_FORK_SERVER', None)
        else:
            os.environ['ROBOT_LAB_FORK_SERVER'] = saved
    med = {m: statistics.median(v) for m, v in cpu.items()}
    print(f"package submission CPU (job, launcher, nodes): nodes exec'd {med['0']:.2f} s, "
          f"forked {med['1']:.2f} s ({med['1'] / med['0']:.2f}x); wall "
          f"{statistics.median(wall['0']):.2f} -> {statistics.median(wall['1']):.2f} s")


def bench_packages(args: argparse.Namespace) -> None:
    from robot_lab.grading.package.grade import grade_package, resolve_rubric
    from robot_lab.grading.package.submission import Submission

    rubric = resolve_rubric('ch6-lab1', None)
    reference = kit_root() / 'tests' / 'data' / 'class_ch6' / 'reference'
    reports = []

    def one() -> None:
        reports.append(grade_package(Submission('reference', reference), rubric))

    median, times = timed(one, args.runs)
    scores = sorted({f'{r.score:g}/{r.max_score:g}' for r in reports})
    runs = ', '.join(f'{t:.1f}' for t in times)
    print(f'package submission, --jobs 1: median {median:.2f} s per submission '
          f'(runs {runs}; scores {", ".join(scores)})')
    if args.busy:
        reports.clear()
        with busy_loops(args.busy):
            loaded, times = timed(one, args.runs)
        scores = sorted({f'{r.score:g}/{r.max_score:g}' for r in reports})
        runs = ', '.join(f'{t:.1f}' for t in times)
        print(f'package submission beside {args.busy} busy loops: median {loaded:.2f} s '
              f'(runs {runs}; scores {", ".join(scores)})')
    bench_sandbox_cost(args, one, median)
    bench_fork_cost(args, one)
    with tempfile.TemporaryDirectory() as tmp:
        class_dir = Path(tmp) / 'class'
        for i in range(args.class_size):
            shutil.copytree(reference, class_dir / f'student{i:02d}')
        cmd = [str(BIN / 'robot-lab'), 'grade', str(class_dir), '--lab', 'ch6-lab1',
               '-o', str(Path(tmp) / 'out'), '--jobs', '2']
        start = time.monotonic()
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                text=True)
        grader = psutil.Process(proc.pid)
        peak_own = peak_tree = 0
        while proc.poll() is None:
            own, tree = _tree_rss(grader)
            peak_own, peak_tree = max(peak_own, own), max(peak_tree, tree)
            time.sleep(0.2)
        wall = time.monotonic() - start
        out = proc.stdout.read() if proc.stdout else ''
        full = sum(1 for line in out.splitlines() if line.endswith(': 13/13'))
        print(f'class of {args.class_size} packages, --jobs 2: {wall / 60:.2f} min '
              f'({wall / args.class_size:.1f} s per submission; {full} at full marks; '
              f'exit {proc.returncode})')
        print(f'grader peak memory: {peak_own / 2**20:.0f} MB (its own process), '
              f'{peak_tree / 2**20:.0f} MB with its jobs and their nodes')


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--domain', type=int, default=96, help='first ROS domain used')
    parser.add_argument('--jobs', type=int, default=4, help='-j for the exercise batch')
    parser.add_argument('--only', choices=('all', 'notebooks', 'packages'), default='all')
    parser.add_argument('--busy', type=int, default=3,
                        help='busy loops beside a second per-package run (0: none)')
    parser.add_argument('--class-size', type=int, default=30,
                        help='package submissions in the class run (default: 30)')
    args = parser.parse_args()
    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    root = kit_root()
    print(f'load average at start: {os.getloadavg()[0]:.2f}')
    if args.only in ('all', 'packages'):
        bench_packages(args)
        if args.only == 'packages':
            print(f'load average at end: {os.getloadavg()[0]:.2f}')
            return

    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / 'empty.ipynb'
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_code_cell('import robot_lab.grading')]
        empty.write_text(nbformat.writes(nb))
        # Only the kernel's fixed cost: `grade` refuses a notebook that is no exercise.
        median, _ = timed(lambda: NotebookClient(nbformat.read(empty, 4),
                                                 kernel_name='robot_lab').execute(), args.runs)
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
