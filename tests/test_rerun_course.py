"""Every cell is safe to run again: Run All twice on each notebook, in course order, then 01
once more after 08 (the order a student who goes back meets).

Each notebook runs in one kernel (nbclient), all its cells and then all of them again; a
cell that hangs fails the run (no cell of the course needs a minute). No cell may end in an
error, and at the end nothing may be left running: no child process of the kernel, no node
spinning in it. Seen before: re-running 01 after 02 hung on `ros2 run … | tail -n 1`, which
ran the sensor for ever once 02 had written it.
"""

from __future__ import annotations

import pytest
from course_run import COURSE, Course, error, source, text


@pytest.fixture(scope='module')
def course(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> Course:
    return Course(tmp_path_factory.mktemp('course') / 'ws', ros_domain)


def _run_all(course: Course, name: str, times: int) -> None:
    cells = list(source(name).cells) * times
    left = course.run(name, cells)
    failed = [f'cell {i % len(cells) if times == 1 else i}:\n{c.source}\n{text(c)}'
              for i, c in enumerate(course.cells[:-1]) if error(c) is not None]
    assert not failed, '\n\n'.join(failed)
    assert left == {'children': [], 'nodes': []}, left


@pytest.mark.parametrize('name', COURSE)
def test_run_all_twice_in_course_order(course: Course, name: str) -> None:
    _run_all(course, name, times=2)


def test_01_again_after_08(course: Course) -> None:
    _run_all(course, '01_create_package', times=1)
