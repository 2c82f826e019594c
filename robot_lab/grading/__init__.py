"""Check cells and lesson set-up for the course notebooks.

`from robot_lab.grading import check, setup`: `setup('04_parameters')` in a notebook's
first cell, `check.nodes_running([...])` and friends after each step.
For instructors: `build_exercises()`, `grade_many()` and `release_course()` (loaded on
first use: nbformat is slow to import, and notebooks only need the checks). One submission:
`robot_lab.grading.notebook.grade.grade(path)` (the module shares the function's name).
"""

from __future__ import annotations

import importlib
from typing import Any

from robot_lab.grading import check
from robot_lab.grading.check import CheckError
from robot_lab.grading.course import Lesson, setup

__all__ = [
    'CheckError',
    'GradeResult',
    'Lesson',
    'build_exercises',
    'check',
    'grade_many',
    'release_course',
    'setup',
]

_LAZY = {
    'GradeResult': 'robot_lab.grading.notebook.grade',
    'build_exercises': 'robot_lab.grading.exercises',
    'grade_many': 'robot_lab.grading.notebook.batch',
    'release_course': 'robot_lab.grading.release',
}


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    return getattr(importlib.import_module(_LAZY[name]), name)
