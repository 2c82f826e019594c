"""The mistake path's walk: a notebook's ladders (wrong answers, then the right one), then
Run All again in the same kernel; and 01 once more in a workspace later lessons filled.

tests/test_mistake_path.py (01–06) and tests/test_mistake_path_capstone.py (07–08) walk
with it; tests/test_mistake_path.py's docstring says what a walk promises.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from course_run import Course, error, fresh, source, student_cells, text
from mistakes import LADDERS
from nbformat import NotebookNode

__all__ = ['answers_and_checks', 'ladder_notebook', 'once_more_01', 'standalone_walk', 'walk']


def answers_and_checks(nb: list[NotebookNode]) -> dict[str, tuple[int, int]]:
    """Answer cell id -> (its index, the index of the first check after it)."""
    found = {}
    for i, cell in enumerate(nb):
        meta = cell.get('metadata', {}).get('nbgrader', {})
        if meta.get('solution') and cell.cell_type == 'code':
            check = next(j for j in range(i + 1, len(nb))
                         if nb[j].get('metadata', {}).get('nbgrader', {}).get('grade'))
            found[meta['grade_id']] = (i, check)
    return found


def _rung_cell(cell: NotebookNode, source_text: str | None = None) -> NotebookNode:
    made = fresh(cell, source_text)
    made.metadata['ladder'] = True  # a step of the mistake path: it may fail
    return made


@dataclass
class Rung:
    answer: str
    mistake: str
    says: str
    check_at: int


def ladder_notebook(name: str) -> tuple[list[NotebookNode], list[Rung]]:
    """The notebook with, before each answer cell, its ladder: the released (unanswered)
    cell and each wrong answer, each followed by the cells between answer and check and by
    the check. The notebook's own answer and check follow: the right answer, same kernel."""
    cells = list(source(name).cells)
    student = student_cells(name)
    by_id = {c.get('id'): c for c in cells}
    out: list[NotebookNode] = []
    rungs: list[Rung] = []
    places = {at: (answer, check) for answer, (at, check) in answers_and_checks(cells).items()}
    for i, cell in enumerate(cells):
        if i in places:
            answer, check = places[i]
            ladder = LADDERS[answer]
            between = [c.get('id') for c in cells[i + 1:check] if c.cell_type == 'code']
            default = ladder.rerun if ladder.rerun is not None else between
            steps = [(student[cell.id].source, 'unanswered', ladder.unanswered, default)]
            steps += [(w.edit(cell.source), w.mistake, w.says,
                       w.rerun if w.rerun is not None else default) for w in ladder.wrong]
            for text_, mistake, says, rerun in steps:
                out.append(_rung_cell(cell, text_))
                out += [_rung_cell(by_id[c]) for c in rerun]
                rungs.append(Rung(answer, mistake, says, len(out)))
                out.append(_rung_cell(cells[check]))
        if cell.get('metadata', {}).get('nbgrader', {}).get('grade') and \
                any(check == i for _a, check in places.values()):
            answer = next(a for a, c in places.values() if c == i)
            rungs.append(Rung(answer, 'right', '', len(out)))
        out.append(cell)
    return out, rungs


def _plain(shown: str) -> str:
    return re.sub(r'\x1b\[[0-9;]*m', '', shown)


def _one_line(shown: str) -> None:
    plain = _plain(shown)
    lines = [ln for ln in plain.splitlines() if ln.strip()]
    assert lines[0].startswith('✗ expected ') and '; observed ' in lines[0], plain
    assert lines[1].startswith('Try: '), plain
    # no frame of the kit's (a path in a student's output may name the kit's folder)
    assert not re.search(r'robot_lab/grading/check/\w+\.py|Traceback', plain), plain


def walk(course: Course, name: str) -> None:
    """Each ladder of `name`, then Run All again: every check names its mistake."""
    cells, rungs = ladder_notebook(name)
    again = list(source(name).cells)  # Run All once more, after the right answers
    left = course.run(name, cells + again)
    ran = course.cells
    for rung in rungs:
        cell = ran[rung.check_at]
        failure = error(cell)
        if rung.mistake == 'right':
            assert failure is None, f'{rung.answer}: the right answer failed:\n{text(cell)}'
            continue
        assert failure is not None, f'{rung.answer} ({rung.mistake}) passed:\n{text(cell)}'
        shown = '\n'.join(failure.traceback)
        print(f'| {rung.answer} | {rung.mistake} |', ' '.join(_plain(shown).splitlines()[:2]))
        _one_line(shown)
        assert re.search(rung.says, _plain(shown), re.S), \
            f'{rung.answer} ({rung.mistake}): the check said\n{shown}'
    errors = [(_where(i, len(cells)), text(c)) for i, c in enumerate(ran)
              if error(c) is not None and not c.get('metadata', {}).get('ladder')]
    assert not errors, errors
    assert left == {'children': [], 'nodes': []}, left


def _where(index: int, ladder: int) -> str:
    return f'cell {index}' if index < ladder else f'Run All again, cell {index - ladder}'


def once_more_01(course: Course) -> None:
    """01 in a workspace the later lessons filled: every cell still runs, nothing is left."""
    left = course.run('01_create_package', list(source('01_create_package').cells))
    failed = [f'cell {i}:\n{c.source}\n{text(c)}'
              for i, c in enumerate(course.cells[:-1]) if error(c) is not None]
    assert not failed, '\n\n'.join(failed)
    assert left == {'children': [], 'nodes': []}, left


def standalone_walk(name: str) -> tuple[Any, Any]:
    """The fixture and the test of a lesson that stands alone (11, 12, 13): its walk in a
    workspace and ROS domain of its own, one module each, so xdist hands them to different
    workers. In the module: `course, test_every_answer_cell_walks_its_ladder_then_runs_again
    = standalone_walk(NAME)`."""
    import pytest

    @pytest.fixture(scope='module')
    def course(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> Course:
        return Course(tmp_path_factory.mktemp('course') / 'ws', ros_domain)

    @pytest.mark.timeout(900)
    def test_every_answer_cell_walks_its_ladder_then_runs_again(course: Course) -> None:
        walk(course, name)

    return course, test_every_answer_cell_walks_its_ladder_then_runs_again
