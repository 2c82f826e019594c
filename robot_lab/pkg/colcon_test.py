"""`colcon test` + `colcon test-result` for a built workspace, as data.

colcon runs each package's tests (pytest for ament_python: the package's `test/`,
including the ament linters) and writes JUnit files; `colcon test-result --verbose`
summarises them as `Summary: N tests, E errors, F failures, S skipped` and lists each
failing case. The grader's optional `tests_pass` check and the notebooks read this.
"""

from __future__ import annotations

import re
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.env import ros_environment
from robot_lab.pkg.build import colcon_executable

__all__ = ['TestRun', 'colcon_test']

_SUMMARY = re.compile(r'^Summary: (\d+) tests?, (\d+) errors?, (\d+) failures?, (\d+) skipped')
_CASE = re.compile(r'^- (\S+) (\S+)$')


@dataclass
class TestRun:
    """What `colcon test-result --verbose` said about a workspace's tests."""

    tests: int = 0
    errors: int = 0
    failures: int = 0
    skipped: int = 0
    failed_cases: list[str] = field(default_factory=list)  # 'pkg test.module.case'
    output: list[str] = field(default_factory=list)
    timed_out: bool = False
    summary: str = ''  # colcon's words: '3 tests, 0 errors, 1 failure, 1 skipped'

    @property
    def ok(self) -> bool:
        return not self.timed_out and self.tests > 0 and not (self.errors or self.failures)


def colcon_test(workspace: str | Path, packages: Sequence[str] = (),
                timeout: float = 300.0, pytest_args: Sequence[str] = ()) -> TestRun:
    """Run `colcon test` (only `packages`, if given) in a built workspace, then read
    `colcon test-result --verbose`; at most `timeout` seconds in all. `pytest_args` go to
    pytest as `--pytest-args` (a test file: only that file's tests, linters left out)."""
    root = Path(workspace).resolve()
    colcon = str(colcon_executable())
    select = ['--packages-select', *packages] if packages else []
    if pytest_args:
        select += ['--pytest-args', *pytest_args]
    env = ros_environment()
    run = TestRun()
    try:
        tested = subprocess.run([colcon, 'test', *select], cwd=root, env=env, text=True,
                                capture_output=True, timeout=timeout, check=False)
        run.output += (tested.stdout + tested.stderr).splitlines()
        result = subprocess.run([colcon, 'test-result', '--verbose', '--test-result-base',
                                 str(root / 'build')], cwd=root, env=env, text=True,
                                capture_output=True, timeout=60, check=False)
    except subprocess.TimeoutExpired:
        run.timed_out = True
        return run
    lines = (result.stdout + result.stderr).splitlines()
    run.output += lines
    for line in lines:
        if (m := _SUMMARY.match(line)) is not None:
            run.tests, run.errors, run.failures, run.skipped = (int(g) for g in m.groups())
            run.summary = line.removeprefix('Summary: ')
        elif (case := _CASE.match(line)) is not None:
            run.failed_cases.append(f'{case[1]} {case[2]}')
    return run
