"""Checks of a student's own unit tests (a package's `test/` folder, Chapter 6): `colcon
test` runs them and they pass, and they fail for a node that is wrong on purpose (a test
that cannot fail checks nothing)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.grading.check.base import CheckError, judged, passed

if TYPE_CHECKING:
    from robot_lab.pkg.colcon_test import TestRun

__all__ = ['tests_catch', 'tests_pass']


_ANSI = re.compile(r'\x1b\[[0-9;]*m')


def _verdicts(log: Path, run: TestRun) -> list[str]:
    """pytest's one-line verdicts (`FAILED test/…::test_x - assert …`) from colcon's log of
    the run; else `colcon test-result --verbose`'s cases and messages."""
    lines = [_ANSI.sub('', line) for line in
             (log.read_text(errors='replace').splitlines() if log.is_file() else [])]
    found = [line for line in lines if line.startswith(('FAILED ', 'ERROR '))]
    if found:
        return found[:8]
    shown, case, inside = [], '', False
    for line in run.output:
        if line.startswith('- '):
            case = line[2:].strip()
        elif line.strip().startswith('<<<'):
            inside = True
        elif line.strip() == '>>>':
            inside = False
        elif inside and line.strip():
            shown.append(f'{case}: {line.strip()}')
            inside = False  # the first line of each message
    return shown[:8]


@judged
def tests_pass(workspace: str | Path, package: str, test_file: str,
               timeout: float = 180.0) -> None:
    """`colcon test` runs the tests in `test_file` (a path in the package) and all pass.

    Only that file: `--pytest-args` leaves out the ament linters, which a plain `colcon
    test` runs too.
    """
    from robot_lab.pkg.colcon_test import colcon_test

    root = Path(workspace)
    run = colcon_test(root, [package], timeout, pytest_args=[test_file])
    expected = f'`colcon test` to run the tests in {test_file} and all to pass'
    verdicts = _verdicts(root / 'log' / 'latest_test' / package / 'stdout_stderr.log', run)
    if run.timed_out:
        raise CheckError(expected, f'they did not finish within {timeout:g} s',
                         'look for a test that waits forever (a spin without a timeout)')
    if run.tests == 0 and not run.summary:
        raise CheckError(expected, '`colcon test-result` found no results',
                         'build the package first (run the colcon build cell), then this '
                         'check again', run.output[-4:], 'What colcon said last:')
    if run.errors:
        raise CheckError(expected, f'{test_file} did not load ({run.summary})',
                         'read the error below: a typo, or a name your test imports that '
                         'your package does not have', verdicts, 'What pytest said:')
    if run.tests == 0 or run.tests == run.skipped:
        raise CheckError(expected, f'colcon test found no tests in {test_file}',
                         'pytest runs functions whose names start with test_ (and that take '
                         'the fixture they use as an argument)')
    if run.failures:
        raise CheckError(expected, f'{run.failures} of {run.tests} failed',
                         'a failing test means your test and your node disagree: check the '
                         'expected value against the rule you implemented',
                         verdicts, 'What pytest said:')
    passed(f'`colcon test` runs {run.tests} test{"s" if run.tests != 1 else ""} in '
           f'{test_file}: all pass')


@judged
def tests_catch(package_dir: str | Path, test_file: str, node: str, topic: str,
                wrong: Mapping[str, Mapping[str, Any]], timeout: float = 120.0) -> None:
    """The tests in `test_file` fail for each wrong version of `node` ('module:Class'):
    `wrong` maps what that version does (for the student) to the one message it publishes
    on `topic` whatever it receives."""
    from robot_lab.env import ros_environment

    root = Path(package_dir)

    def expected(does: str) -> str:
        return f'your tests in {test_file} to fail for a node that {does}'

    for does, message in wrong.items():
        spec = json.dumps({'node': node, 'topic': topic, 'message': dict(message)})
        env = ros_environment({'ROBOT_LAB_WRONG_NODE': spec})
        env['PYTHONPATH'] = str(root) + (f':{env["PYTHONPATH"]}' if env.get('PYTHONPATH')
                                         else '')
        try:
            run = subprocess.run([sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
                                  '-p', 'robot_lab.grading.check.wrong_node', test_file],
                                 cwd=root, env=env, capture_output=True, text=True,
                                 timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            raise CheckError(expected(does), f'they did not finish within {timeout:g} s',
                             'look for a test that waits forever') from None
        if run.returncode == 0:
            raise CheckError(expected(does),
                             'they all pass for it, so they cannot tell it from yours',
                             'assert the exact value your node must publish for a given '
                             'input (pytest.approx for floats), for more than one input')
        if run.returncode != 1:  # 1: tests failed, as they should; others: pytest could not run
            raise CheckError(expected(does), f'pytest could not run them (exit code '
                             f'{run.returncode})', 'make the check above pass first',
                             run.stdout.splitlines()[-6:], 'What pytest said:')
    passed(f'your tests fail for a node that {" and for one that ".join(wrong)}')
