"""`builds`: `colcon build` finishes without errors."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict, code

__all__ = ['builds']


@register('builds', stage='build')
def builds(state: JobState, check: RubricCheck) -> Verdict:
    expected = '`colcon build` finishes without errors'
    if state.built:
        return Verdict(True, expected, state.build_note)
    return Verdict(False, expected, 'the build failed; colcon says:' + code(state.build_lines, 20),
                   'fix the file and line named above, then run `colcon build` yourself '
                   'before handing in')
