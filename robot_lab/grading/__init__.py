"""Check cells and lesson set-up for the course notebooks.

`from robot_lab.grading import check, setup`: `setup('04_parameters')` in a notebook's
first cell, `check.nodes_running([...])` and friends after each step.
"""

from __future__ import annotations

from robot_lab.grading import check
from robot_lab.grading.check import CheckError
from robot_lab.grading.course import Lesson, setup

__all__ = ['CheckError', 'Lesson', 'check', 'setup']
