"""The mistake path of 07 (the capstone) and 08 (debugging), then 01 once more after 08.

As tests/test_mistake_path.py walks 01–06 (its docstring says how), in a workspace of its
own: these two lessons write packages of their own (multi_node_robot, broken_robot), and
going back to 01 then builds beside them (`colcon build` builds every package it finds).

Between them, notebook 07's promise: the package its answers leave in an empty workspace
earns full marks from the instructor's grader, `robot-lab grade --lab ch6-lab1`, run here
apart from the notebook's own grading cell (which is not trusted for this).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from conftest import run_cli
from course_run import COURSE, Course
from mistake_walk import once_more_01, walk


@pytest.fixture(scope='module')
def course(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> Course:
    return Course(tmp_path_factory.mktemp('course') / 'ws', ros_domain)


# 07's walk took 176 s idle and up to 237 s beside two busy loops (13 clean-clone runs):
# pytest's 300 s is a hang guard, and 79 % of it is too close for a crowded host.
@pytest.mark.timeout(900)
@pytest.mark.parametrize('name', COURSE[7:])
def test_every_answer_cell_walks_its_ladder_then_runs_again(course: Course, name: str) -> None:
    walk(course, name)


def test_the_capstone_package_earns_full_marks(course: Course, tmp_path: Path) -> None:
    package = course.workspace / 'src' / 'multi_node_robot'
    assert (package / 'package.xml').is_file(), 'notebook 07 left no package'
    out = tmp_path / 'report'
    result = run_cli('grade', str(package), '--lab', 'ch6-lab1', '-o', str(out),
                     '--domain-id', str(course.domain), timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr
    with (out / 'grades.csv').open(newline='') as f:
        (row,) = list(csv.DictReader(f))
    scores = json.loads((out / 'results' / f'{row["student"]}.json').read_text())
    lost = [t['name'] for t in scores['tests'] if t['score'] < t['max_score']]
    feedback = (out / 'feedback' / f'{row["student"]}.md').read_text()
    assert not lost and float(row['score']) == float(row['max_score']), \
        f'checks that lost points: {lost}\n{feedback}'


def test_01_again_after_08(course: Course) -> None:
    once_more_01(course)
