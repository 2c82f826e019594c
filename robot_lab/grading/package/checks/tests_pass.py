"""`tests_pass` (optional, off in the shipped rubric): the package's own `colcon test`
passes, its linters (flake8, pep257, copyright) included."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict, code

__all__ = ['tests_pass']


@register('tests_pass', stage='build')
def tests_pass(state: JobState, check: RubricCheck) -> Verdict:
    from robot_lab.pkg.colcon_test import colcon_test

    expected = '`colcon test` passes (the tests in test/ and the ament linters)'
    if not state.built or state.package is None:
        return Verdict(False, expected, 'not tested: the package does not build',
                       'make `colcon build` succeed first')
    ws = state.package.parent.parent
    run = colcon_test(ws, [state.package_name], float(check.option('timeout_seconds', 180)))
    if run.timed_out:
        return Verdict(False, expected, 'the tests did not finish in time',
                       'look for a test that waits forever (a spin without a timeout)')
    if run.tests == 0:
        return Verdict(False, expected, 'no tests ran',
                       'keep the test/ folder ros2 pkg create made and add your own test_*.py')
    if not run.ok:
        return Verdict(False, expected, f'{run.summary}; failing:' + code(run.failed_cases, 10),
                       'run `colcon test --packages-select ' + state.package_name
                       + '` then `colcon test-result --verbose` and fix what it names')
    return Verdict(True, expected, run.summary)
