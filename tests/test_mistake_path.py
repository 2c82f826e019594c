"""The mistake path: every answer cell of 01–06 answered as a student does, in one kernel,
then Run All once more in that kernel (every cell is safe to run again). The capstone and
debugging lessons (07–08) walk theirs in tests/test_mistake_path_capstone.py, beside this.

For each answer cell: the student's copy as released (unanswered), then one or two plausible
wrong answers, then the right one, each followed by its check, in the notebook's own kernel
(nbclient). Each failing check must name its mistake (tests/mistakes.py is the course's
table of mistakes and messages); the right answer must pass with no restart. Then every cell
of the notebook runs again in the same kernel, in course order, and 01 once more at the end
(after 06 here, after 08 there: the order a student who goes back meets): no cell of the
course may end in an error on any run, a cell that hangs fails the run (no cell needs a
minute), and nothing may be left running at the end (no child process, no node spinning
in the kernel). Seen before: re-running 01 after 02 hung on `ros2 run … | tail -n 1`, which
ran the sensor for ever once 02 had written it.

One kernel does both (a ladder, then Run All) so the course starts once per notebook here;
tests/browser runs each notebook once more, from a fresh kernel, and compares the outputs
nbval would compare. 07 and 08 build packages of their own (multi_node_robot, broken_robot),
so they walk in a workspace of their own, on another worker: in one chain the nine ladders
were the run's longest (620 s), and five workers could not share them.
"""

from __future__ import annotations

import pytest
from course_run import COURSE, Course, source
from mistake_walk import answers_and_checks, once_more_01, walk
from mistakes import LADDERS


@pytest.fixture(scope='module')
def course(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> Course:
    return Course(tmp_path_factory.mktemp('course') / 'ws', ros_domain)


@pytest.mark.parametrize('name', COURSE[:7])
def test_every_answer_cell_walks_its_ladder_then_runs_again(course: Course, name: str) -> None:
    walk(course, name)


def test_01_again_after_06(course: Course) -> None:
    once_more_01(course)


def test_every_answer_cell_has_a_ladder() -> None:
    # 11, 12, 13: tests/test_mistake_path_tf2.py, _description.py and _simulation.py
    walked = [*COURSE, '11_tf2_turtlesim', '12_robot_description', '13_simulation']
    ids = {i for name in walked for i in answers_and_checks(list(source(name).cells))}
    assert set(LADDERS) == ids
