"""The mistake path of 07 (the capstone) and 08 (debugging), then 01 once more after 08.

As tests/test_mistake_path.py walks 01–06 (its docstring says how), in a workspace of its
own: these two lessons write packages of their own (multi_node_robot, broken_robot), and
going back to 01 then builds beside them (`colcon build` builds every package it finds).
"""

from __future__ import annotations

import pytest
from course_run import COURSE, Course
from test_mistake_path import once_more_01, walk


@pytest.fixture(scope='module')
def course(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> Course:
    return Course(tmp_path_factory.mktemp('course') / 'ws', ros_domain)


@pytest.mark.parametrize('name', COURSE[7:])
def test_every_answer_cell_walks_its_ladder_then_runs_again(course: Course, name: str) -> None:
    walk(course, name)


def test_01_again_after_08(course: Course) -> None:
    once_more_01(course)
